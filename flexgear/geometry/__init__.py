"""Geometry: involute gear sets, tooth profiles, component layout, solids, mass properties, checks."""
