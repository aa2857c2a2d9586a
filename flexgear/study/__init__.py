"""Variant studies: the matrix runner, screening (Westgard), comparisons, sweeps, run-up maps."""
