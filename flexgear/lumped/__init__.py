"""Lumped-parameter model (the study's eq. 1-13, any arrangement): parameters and assembly, time integration, modes."""
