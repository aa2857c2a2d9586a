"""FE stage: meshes of the components, FE models, Craig-Bampton reduction, reduced-body cache, export."""
