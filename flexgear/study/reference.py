"""The study's published numbers (You et al., GTF gearbox), each with its table."""

from __future__ import annotations

import numpy as np

STUDY_TABLE6 = {  # Table 6 of the study: theory, ADAMS multibody (model 4), Matlab lumped-parameter model
    "input_speed_deg_per_s": (36000.0, 36000.0, 36000.0),
    "output_speed_deg_per_s": (-11647.0554, -11647.0554, -11647.0550),
    "outer_mesh_force_n": (798.1894, 800.7533, 798.1762),
    "inner_mesh_force_n": (798.1894, 797.5522, 798.1764),
    "input_bearing_peak_accel_m_per_s2": (np.nan, 0.15, 0.23),
    "output_bearing_peak_accel_m_per_s2": (np.nan, 0.14, 0.24),
}


STUDY_TABLE7 = {1: (0.0549, 0.0590, 0.0621, 0.0860), 2: (0.0020, 0.0008, 0.0033, 0.0105),
             4: (0.0126, 0.0014, 0.0040, 0.0135), 6: (0.0094, 0.0015, 0.0007, 0.0047),
             9: (0.0017, 0.0013, 0.0013, 0.0010)}  # Table 7: MBD input, output; lumped input, output [m/s²]


# Table 4 of the study: ADAMS wall time [s] of each model (1-7) for the full 0.6 s load case
ADAMS_TIME_S = {1: 371.0, 2: 17948.0, 3: 507.0, 4: 34903.0, 5: 11745.0, 6: 35662.0, 7: 42955.0}
ADAMS_SIMULATED_S = 0.6   # section 3.1: the study's runs simulate 0.6 s
