"""Layout of the parameter vectors of the lumped model's compiled kernel (flexgear.lumped.run.LumpedModel ``fp``
and ``ip``): the index of each entry.

Shared by the time model that fills and reads them (flexgear.lumped.run) and by the linearised model that reads
the same vectors (flexgear.harmonic.lumped, flexgear.harmonic.lumped_friction).

Float vector ``fp``: ``MU`` tooth friction coefficient; ``W_IN`` input speed [rad/s]; ``T_RAMP`` ramp time [s];
``R_C`` carrier speed over input speed; ``T_LOAD`` load torque [N m]; ``LOAD_SIGN`` its sign on the output member;
``IMPACT`` 1 under the impact law, else 0; ``EXPONENT`` and ``DEPTH`` [m] the impact law's exponent and
penetration depth; ``NFP`` the vector's length.

Integer vector ``ip``: ``IN_SPIN`` and ``OUT_SPIN`` the coordinates of the input and output spins; ``IN_BODY`` and
``OUT_BODY`` the bodies whose bearings give the input and output accelerations; ``NIP`` the vector's length.
"""

__all__ = ["MU", "W_IN", "T_RAMP", "R_C", "T_LOAD", "LOAD_SIGN", "IMPACT", "EXPONENT", "DEPTH", "NFP",
           "IN_SPIN", "OUT_SPIN", "IN_BODY", "OUT_BODY", "NIP"]

MU, W_IN, T_RAMP, R_C, T_LOAD, LOAD_SIGN, IMPACT, EXPONENT, DEPTH, NFP = range(10)
IN_SPIN, OUT_SPIN, IN_BODY, OUT_BODY, NIP = range(5)
