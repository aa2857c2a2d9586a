"""Lumped-parameter model of the study (eq. 1-13): parameters and assembly, time integration, modes."""
