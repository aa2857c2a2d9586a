"""Physics laws as small functions: gear contact (numpy/symbolic and compiled twins), STEP ramps."""
