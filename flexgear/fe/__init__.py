"""FE stage: meshes of the components, FE models, Craig-Bampton reduction, reduced-body cache, export."""

from flexgear.fe import imported as _imported  # noqa: F401,E402  (registers the reader of [components_geometry] parts)
from flexgear.fe import imported_mass as _imported_mass  # noqa: F401,E402  (registers their exact mass properties)
