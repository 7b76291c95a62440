"""A whole audit as a library call: the run, its JSON document, what it did not check, the 3D check, the baseline.

``wgcad audit`` is this plus argument parsing, files and printing; a library
user (a CI script, a regression test) gets the same document and verdict
from :func:`audit_document` without the CLI.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..placement.imperfect import Imperfections
from ..regression import baseline_figures, compare, make_baseline
from ..report.audit import audit_json
from ..report.notes import not_modelled
from ..report.sections import balanced_taper, section_rows
from .audit import RunSettings, audit_settings, run_audit

__all__ = ["AuditReport", "audit_document", "baseline_document", "imperfect_not_checked"]


@dataclass(slots=True)
class AuditReport:
    """An audit with its document: ``doc`` is the JSON of ``wgcad audit --json``; ``drifts`` the baseline's (or None)."""

    drive: object
    result: object
    doc: dict
    drifts: list | None = None

    @property
    def failed(self) -> bool:
        """Interference, or a figure drifted from the baseline: the CLI's exit code 1."""
        return bool(self.drifts) or bool(self.doc["interference"])


def imperfect_not_checked(settings: dict, plot: bool = False) -> list[str]:
    """What the audit of an imperfect drive (wgcad.clearance.imperfect) leaves to the perfect drive, said in the summary."""
    notes = []
    full = settings.get("full_cycle_turns")
    done = settings.get("generator_turns", 1.0)
    if not settings.get("shortcuts_that_hold", {}).get("one_generator_turn", True) and full and done < full - 1e-9:
        notes.append(
            f"generator turns beyond the first {done:g} of the {full}-turn cycle: the flexspline-borne errors "
            f"(run-out, eccentricity, e_h^g) meet the housing's and the cam's in other phases there "
            f"(--turns full sweeps all {full}, {full / max(done, 1e-9):g}x the samples)"
        )
    if plot:
        notes.append(
            "--plot with [imperfections]: the profile picture shows the perfect drive's passage (the vs_angle picture "
            "shows every imperfect passage's entry gap, the tightest-spot picture the imperfect parts)"
        )
    return notes


def audit_document(
    design_path,
    rs: RunSettings,
    engine: str = "2d",
    baseline: dict | None = None,
    baseline_path=None,
    plot: bool = False,
    progress=None,
    on_stage=None,
    by_section: bool = False,
) -> AuditReport:
    """Audit a design and shape the document ``wgcad audit --json`` writes.

    Parameters
    ----------
    design_path : path of the design file
    rs : RunSettings
    engine : {"2d", "fcl", "both"}
        With "fcl"/"both" the pairs the 2D engine singles out are checked
        again in 3D with python-fcl (``doc["fcl"]``).
    baseline : dict, optional
        A baseline (:func:`wgcad.regression.load_baseline`): its figures are
        compared (``doc["baseline"]``, ``AuditReport.drifts``).
    plot : bool
        Pictures will be drawn: the notes say what they show of an imperfect drive.
    progress : callable, optional
        ``progress(done, total, stage)`` of the 2D engine.
    on_stage : callable, optional
        ``on_stage(name)`` before the 3D check (a progress bar's label).
    by_section : bool
        Audit each section of a coned cup on its own as well (``doc["by_section"]``: tooth offset, depth of
        engagement, smallest clearance; :mod:`wgcad.report.sections`). Perfect drives only.
    """
    drive, result = run_audit(design_path, rs, progress=progress)
    doc = audit_json(result)
    doc["design"] = drive.design.drive.name
    doc["source"] = drive.design.source
    imperfect = bool(doc["settings"].get("imperfections"))
    doc["not_checked"] = not_modelled(drive.design, "this audit", imperfections=imperfect)
    if imperfect:
        doc["not_checked"] += imperfect_not_checked(doc["settings"], plot=plot)
    if by_section:
        if imperfect:
            doc["not_checked"].append(
                "--by-section: the sections of the imperfect drive (it audits the perfect one only)"
            )
        else:
            if on_stage is not None:
                on_stage("section by section")
            settings = audit_settings(drive, rs)
            doc["by_section"] = section_rows(drive, settings)
            doc["balanced_taper"] = balanced_taper(drive, settings)
    if engine in ("fcl", "both"):
        if on_stage is not None:
            on_stage("3D check (fcl)")
        from ..clearance.fcl3d import verify_worst
        from ..report.check3d import check3d_document

        imp = None
        if imperfect:
            imp = Imperfections.from_spec(drive.design.imperfections)
        doc["fcl"] = check3d_document(verify_worst(drive, result, imp=imp))
        doc["settings"]["engine"] = (
            "fcl (3D check of the pairs the 2D engine singles out)" if engine == "fcl" else "2d + fcl"
        )
    drifts = None
    if baseline is not None:
        drifts = compare(baseline, baseline_figures(drive, doc))
        doc["baseline"] = {"path": str(baseline_path), "drifts": [d.__dict__ for d in drifts]}
    return AuditReport(drive, result, doc, drifts)


def baseline_document(run: AuditReport, settings, design_source: str) -> dict:
    """The geometry regression baseline of the audit ``run`` (what ``wgcad audit --write-baseline`` writes): its
    figures with the run settings a later comparison must repeat (:class:`wgcad.audit.RunSettings` ``settings``)."""
    kept = ("step_deg", "sections", "chord_tol_um", "interference_tol_um")
    return make_baseline(
        str(design_source), {k: v for k, v in settings.as_dict().items() if k in kept}, run.drive, run.doc
    )
