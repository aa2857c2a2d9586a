"""Modal analysis of a gearbox variant at its operating point.

:func:`linearize` (flexgear.modal.linear): the multibody model of any variant, rigid or flexible, linearised at its
static equilibrium under the load torque at the input speed; :func:`modes` (flexgear.modal.modes): its natural
frequencies, damping ratios, mode shapes, cyclic-symmetry kinds and energy shares per component.
"""

from flexgear.modal.linear import Coordinate, LinearModel, linearize
from flexgear.modal.modes import Modes, modes

__all__ = ["Coordinate", "LinearModel", "Modes", "linearize", "modes"]
