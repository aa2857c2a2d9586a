"""Variant studies: the matrix runner, screening (Westgard), comparisons, the study's reference values."""
