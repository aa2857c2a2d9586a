"""Steady harmonic response to the transmission-error excitation over a speed range, in the frequency domain.

:func:`harmonic_response` (the multibody model of a variant, linearised by flexgear.modal.linear) and
:func:`lumped_harmonic_response` (the lumped model, flexgear.lumped): mesh forces, dynamic factor K_v, bearing
accelerations and dynamic transmission error at each mesh harmonic (flexgear.harmonic.response). The names are
imported on first use (PEP 562), so that the command line's parser (flexgear.harmonic.cli) stays light.
"""

__all__ = ["Response", "harmonic_response", "lumped_harmonic_response", "mesh_frequency_hz"]


def __getattr__(name: str):
    if name not in __all__:
        raise AttributeError(f"module 'flexgear.harmonic' has no attribute {name!r}")
    from flexgear.harmonic import lumped, response

    return getattr(lumped if name == "lumped_harmonic_response" else response, name)
