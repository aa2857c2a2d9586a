"""Modal analysis of a gearbox variant at its operating point.

:func:`linearize` (flexgear.modal.linear): the multibody model of any variant, rigid or flexible, linearised at its
static equilibrium under the load torque at the input speed; :func:`modes` (flexgear.modal.eigenmodes): its natural
frequencies, damping ratios, mode shapes, cyclic-symmetry kinds and energy shares per component;
:func:`period_modes` (flexgear.modal.period): the same over one revolution of the flexible gears, each frequency's
mean and spread; :func:`campbell`
(flexgear.modal.campbell_diagram): the Campbell diagram over input speed with the mesh-order crossings;
:func:`modal_screening` (flexgear.modal.screening): which components must be flexible, from the all-flexible variant's
modes. The names are
imported on first use (PEP 562), so that the command line's parser (flexgear.modal.cli) stays light.
"""

from importlib import import_module

_LAZY = {"Coordinate": "linear", "LinearModel": "linear", "linearize": "linear", "Modes": "eigenmodes",
         "modes": "eigenmodes", "Campbell": "campbell_diagram", "campbell": "campbell_diagram",
         "mesh_frequency_hz": "campbell_diagram", "resonant": "campbell_diagram",
         "ModalScreening": "screening", "modal_screening": "screening", "period_modes": "period"}

__all__ = ["Campbell", "Coordinate", "LinearModel", "ModalScreening", "Modes", "campbell", "linearize",
           "mesh_frequency_hz", "modal_screening", "modes", "period_modes", "resonant"]


def __getattr__(name: str):
    if name in _LAZY:
        module = import_module(f"flexgear.modal.{_LAZY[name]}")
        # every name of that submodule at once (the submodules are named apart from their functions, so that
        # importing one never binds a function's name to a module)
        globals().update({n: getattr(module, n) for n, m in _LAZY.items() if m == _LAZY[name]})
        return globals()[name]
    raise AttributeError(f"module 'flexgear.modal' has no attribute {name!r}")
