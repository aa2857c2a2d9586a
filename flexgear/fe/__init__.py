"""FE stage: meshes of the components, FE models, Craig-Bampton reduction, reduced-body cache, export."""

from flexgear.fe import imported as _imported  # noqa: F401,E402  (registers the reader of [components_geometry] parts)
