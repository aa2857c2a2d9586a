"""Multibody model on Exudyn: bodies, elements, gear contacts, gear trains, the study's gearbox, runs."""
