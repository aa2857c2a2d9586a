"""Modal analysis of a gearbox variant at its operating point.

:func:`linearize` (flexgear.modal.linear): the multibody model of any variant, rigid or flexible, linearised at its
static equilibrium under the load torque at the input speed; :func:`modes` (flexgear.modal.modes): its natural
frequencies, damping ratios, mode shapes, cyclic-symmetry kinds and energy shares per component; :func:`campbell`
(flexgear.modal.campbell): the Campbell diagram over input speed with the mesh-order crossings; :func:`modal_screening`
(flexgear.modal.screening): which components must be flexible, from the all-flexible variant's modes. The names are
imported on first use (PEP 562), so that the command line's parser (flexgear.modal.cli) stays light.
"""

from importlib import import_module

_LAZY = {"Coordinate": "linear", "LinearModel": "linear", "linearize": "linear", "Modes": "modes", "modes": "modes",
         "Campbell": "campbell", "campbell": "campbell", "ModalScreening": "screening",
         "modal_screening": "screening"}

__all__ = ["Campbell", "Coordinate", "LinearModel", "ModalScreening", "Modes", "campbell", "linearize",
           "modal_screening", "modes"]


def __getattr__(name: str):
    if name in _LAZY:
        value = getattr(import_module(f"flexgear.modal.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'flexgear.modal' has no attribute {name!r}")
