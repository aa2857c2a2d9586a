"""Modal analysis of a gearbox variant at its operating point.

:func:`linearize` (flexgear.modal.linear): the multibody model of any variant, rigid or flexible, linearised at its
static equilibrium under the load torque at the input speed; :func:`modes` (flexgear.modal.modes): its natural
frequencies, damping ratios, mode shapes, cyclic-symmetry kinds and energy shares per component;
:func:`period_modes` (flexgear.modal.period): the same over one revolution of the flexible gears, each frequency's
mean and spread; :func:`campbell`
(flexgear.modal.campbell): the Campbell diagram over input speed with the mesh-order crossings; :func:`modal_screening`
(flexgear.modal.screening): which components must be flexible, from the all-flexible variant's modes. The names are
imported on first use (PEP 562), so that the command line's parser (flexgear.modal.cli) stays light.
"""

from importlib import import_module

_LAZY = {"Coordinate": "linear", "LinearModel": "linear", "linearize": "linear", "Modes": "modes", "modes": "modes",
         "Campbell": "campbell", "campbell": "campbell", "mesh_frequency_hz": "campbell", "resonant": "campbell",
         "ModalScreening": "screening", "modal_screening": "screening", "period_modes": "period"}

__all__ = ["Campbell", "Coordinate", "LinearModel", "ModalScreening", "Modes", "campbell", "linearize",
           "mesh_frequency_hz", "modal_screening", "modes", "period_modes", "resonant"]


def __getattr__(name: str):
    if name in _LAZY:
        module = import_module(f"flexgear.modal.{_LAZY[name]}")
        # every name of that submodule at once: importing flexgear.modal.modes (.campbell) binds the package's
        # ``modes`` (``campbell``) to the submodule, which the function of the same name must replace; within the
        # package these names are imported from here, so that the functions keep them
        globals().update({n: getattr(module, n) for n, m in _LAZY.items() if m == _LAZY[name]})
        return globals()[name]
    raise AttributeError(f"module 'flexgear.modal' has no attribute {name!r}")
