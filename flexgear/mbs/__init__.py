"""Multibody model on Exudyn: bodies, elements, gear contacts, gear trains, the star, planetary and parallel-axis
stages and their connections, runs."""
