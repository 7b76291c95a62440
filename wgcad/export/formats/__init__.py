"""The file formats wgcad writes and reads back: DXF (with the arcs fitted to the curves), SVG, STL, 3MF, STEP and
the JSON text; the part set's formats behind one registry (:data:`wgcad.export.formats.registry.FORMATS`)."""
