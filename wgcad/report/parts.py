"""The part set's document, ``<design>_parts.json``: the run's settings, the sizes (given or derived, with their
rules and warnings) and each part's volume and figures, rounded (the files' names are added by the writer)."""

from __future__ import annotations

__all__ = ["part_report", "parts_document"]


def _jsonable(v):
    if isinstance(v, dict):
        return {k: _jsonable(x) for k, x in v.items() if k not in ("plug_outline", "neutral_line")}
    if isinstance(v, float):
        return round(v, 6)
    return v


def part_report(part) -> dict:
    """The part's entry of ``<design>_parts.json``: its volume and the figures of its ``info``, rounded."""
    return {"volume_mm3": round(part.volume_mm3, 4), **_jsonable(part.info)}


def parts_document(drive, sizes, source, dxf_style: str, formats: list) -> dict:
    """The document of a part set before its parts are entered (``"parts": {}``; :func:`part_report` fills it)."""
    return {
        "design": str(source),
        "chord_tol_mm": drive.tol,
        "dxf_style": dxf_style,
        # [load] rated_torque_nm: the torque the bolts are sized for, not the datasheet's rated torque (docs/glossary.md)
        "design_torque_nm": drive.design.load.rated_torque_nm,
        "formats": list(formats),
        # only the sizes of parts this drive has (an external drive has no cup and no flange)
        "sizes_mm": _jsonable({k: sizes.values[k] for k in sizes.used if sizes.values.get(k) is not None}),
        "derived_from_gear_size": list(sizes.derived),
        "size_rules": dict(sizes.rules),
        "warnings": list(sizes.notes),
        "parts": {},
    }
