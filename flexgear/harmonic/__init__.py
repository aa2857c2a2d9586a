"""Steady harmonic response to the transmission-error excitation over a speed range, in the frequency domain.

:func:`harmonic_response` (the multibody model of a variant, linearised by flexgear.modal.linear) and
:func:`lumped_harmonic_response` (the lumped model, flexgear.lumped): mesh forces, dynamic factor K_v, bearing
accelerations and dynamic transmission error at each mesh harmonic (flexgear.harmonic.response);
:func:`turning_response`: the same over the angle of a turning asymmetric flexible body (the tied ring's bolt
pattern), with its sidebands and the quasi-static K_v (flexgear.harmonic.turning). The names are imported on first
use (PEP 562), so that the command line's parser (flexgear.harmonic.cli) stays light.
"""

__all__ = ["Response", "harmonic_response", "lumped_harmonic_response", "mesh_frequency_hz", "TurningResponse",
           "turning_response", "turning_pattern"]

_HOME = {"lumped_harmonic_response": "lumped", "TurningResponse": "turning", "turning_response": "turning",
         "turning_pattern": "turning"}


def __getattr__(name: str):
    if name not in __all__:
        raise AttributeError(f"module 'flexgear.harmonic' has no attribute {name!r}")
    import importlib

    return getattr(importlib.import_module(f"flexgear.harmonic.{_HOME.get(name, 'response')}"), name)
