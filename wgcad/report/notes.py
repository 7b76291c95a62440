"""What a command leaves out of a design: said in every summary and JSON document, never silent."""

from __future__ import annotations

__all__ = ["not_modelled"]


def not_modelled(design, command: str, imperfections: bool = False) -> list[str]:
    """What a design's optional tables ask for that ``command`` does not model: said in every summary, never silent.

    ``imperfections``: the command models ``[imperfections]`` (the 2D audit does).
    """
    notes = []
    if design.sectors.active:
        notes.append(
            f"[sectors]: {command} uses the plain rigid gear of drive.z_rigid = {design.drive.z_rigid} teeth; "
            "`wgcad sector` builds and audits the sectored gear"
        )
    if design.imperfections.any and not imperfections:
        why = " (imperfect parts are modelled with a fixed rigid gear only)" if design.drive.fixed != "rigid" else ""
        notes.append(
            f"[imperfections]: {command} uses perfect parts{why}; `wgcad ke` computes the imperfect drive's kinematic error"
        )
    return notes
