"""``rockyade assess --report DIR``: the page of an assessment, written as one result set.

The folder holds ``report.html`` (self-contained: the figures embedded, no script, nothing loaded
from elsewhere), its Markdown twin ``report.md`` and the figures it names as PNG files beside it
(``spectrum.png``, ``mechanism.png``, ``check.png``; ``fragility.png`` and ``selection.png`` when
the dynamics ran and the records are a selection). The page
(:func:`rockyade.assess.report_page.report_page`) is built from the data ``assess.json`` is
written from; the figures are drawn from the same assessment.

The set is replaced as a whole (:mod:`rockyade.io.resultset`, ``report.html`` last): an
interrupted write leaves the previous report whole, and never a mix. A folder that holds files
that are not a report's (another command's set, a scene, anything else) is refused before
anything is drawn.
"""

from __future__ import annotations

import datetime as dt
import importlib.metadata
import platform
import shlex
import subprocess
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from rockyade import __version__
from rockyade.assess.assessment import Assessment
from rockyade.assess.motions import RecordFiles
from rockyade.assess.report_model import (
    FIGURE_CHECK,
    FIGURE_FRAGILITY,
    FIGURE_MECHANISM,
    FIGURE_SELECTION,
    FIGURE_SPECTRUM,
    FIGURES,
    Provenance,
)
from rockyade.assess.report_page import report_page
from rockyade.assess.report_render import render_html, render_markdown
from rockyade.errors import InputError
from rockyade.io.folders import other_files
from rockyade.motion.selection_set import sha256

REPORT_HTML = "report.html"
REPORT_MD = "report.md"
#: The set's files; ``report.html``, written last, marks it complete.
REPORT_SET = (*FIGURES, REPORT_MD, REPORT_HTML)
REPORT_LAST = REPORT_HTML


def check_report_folder(folder: Path, option: str = "--report") -> None:
    """Refuse a folder that is a file, or holds anything but a previous report's files.

    Raises
    ------
    InputError
        Naming ``option``.
    """
    if folder.is_symlink():
        raise InputError(option, f"{folder} is a symbolic link; give a folder")
    if folder.exists() and not folder.is_dir():
        raise InputError(option, f"{folder} is a file; give a folder")
    if not folder.is_dir():
        return
    others = other_files(folder, REPORT_SET)
    links = sorted(p.name for p in folder.iterdir() if p.name in REPORT_SET and p.is_symlink())
    if others or links:
        shown = ", ".join((others + links)[:5]) + (" ..." if len(others + links) > 5 else "")
        raise InputError(
            option,
            f"{folder} holds files that are not an assessment report's ({shown}): give an empty folder, or one a "
            "previous 'assess --report' wrote (its report is then replaced as a whole)",
        )


def _package(name: str) -> str:
    try:
        return importlib.metadata.version(name)
    except importlib.metadata.PackageNotFoundError:
        return "not installed"


def _debian(package: str) -> str:
    """A Debian package's version (``dpkg-query``), or "unknown"."""
    try:
        done = subprocess.run(
            ["dpkg-query", "-W", "-f=${Version}", package], capture_output=True, text=True, timeout=10, check=False
        )
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return done.stdout.strip() if done.returncode == 0 and done.stdout.strip() else "unknown"


def versions(solver: str | None) -> tuple[tuple[str, str], ...]:
    """rockyade's version and those of what the assessment ran: Python, the numerical libraries, the
    limit analysis' linear programmes (HiGHS through SciPy), the dynamics' solver when it ran."""
    out = [
        ("rockyade", __version__),
        ("Python", platform.python_version()),
        ("NumPy", _package("numpy")),
        ("SciPy (the limit analysis' HiGHS linear programmes, scipy.optimize.linprog)", _package("scipy")),
        ("pandas", _package("pandas")),
        ("Matplotlib (the figures)", _package("matplotlib")),
    ]
    if solver == "housner":
        out.append(("the dynamics' solver", f"housner: rockyade {__version__}'s exact solution of Housner's equations"))
    elif solver == "reference":
        out.append(("the dynamics' solver", f"reference: rockyade {__version__}'s DEM (numba {_package('numba')})"))
    elif solver == "yade":
        out.append(("the dynamics' solver", f"yade: YADE (Debian yade {_debian('yade')})"))
    elif solver == "siconos":
        from rockyade.siconos.backend import package_version

        out.append(
            ("the dynamics' solver", f"siconos: Siconos (Debian python3-siconos {package_version() or 'unknown'})")
        )
    elif solver:
        out.append(("the dynamics' solver", solver))
    return tuple(out)


def provenance(
    scene: Path,
    given: Sequence[tuple[str, str]],
    defaults: Sequence[tuple[str, str, str]],
    solver: str | None,
    now: dt.datetime | None = None,
) -> Provenance:
    """The report's :class:`~rockyade.assess.report_model.Provenance`: the scene as given and its
    SHA-256 (read now), the command rebuilt from the options given, the defaults, the versions, the date."""
    words = ["rockyade", "assess", str(scene)]
    for option, value in given:
        words += [option] if value == "" else [option, value]
    when = (now or dt.datetime.now(dt.UTC)).replace(microsecond=0).isoformat()
    return Provenance(
        str(scene),
        sha256(scene),
        shlex.join(words),
        tuple(given),
        tuple(defaults),
        versions(solver),
        when,
    )


def _figures(a: Assessment, title: str) -> Mapping[str, Callable[[Path], Any]]:
    """How each figure of the page is drawn (:data:`rockyade.assess.report_model.FIGURES`)."""

    def spectrum(path: Path) -> None:
        from rockyade.figures.site_spectrum import plot_site_spectrum

        plot_site_spectrum(a, path=path)

    def mechanism(path: Path) -> None:
        from rockyade.figures.canvas import new_figure, save_figure
        from rockyade.figures.collapse_mechanism import draw_mechanism

        polygons = a.limit.model.polygons_m
        xs = np.concatenate([q[:, 0] for q in polygons])
        ys = np.concatenate([q[:, 1] for q in polygons])
        aspect = float(np.ptp(ys)) / max(float(np.ptp(xs)), 1e-9)  # tall walls: a narrower figure
        fig, ax = new_figure(path, figsize=(float(np.clip(4.0 + 4.0 / max(aspect, 0.5), 5.0, 9.0)), 5.5))
        draw_mechanism(a.limit, title=title, ax=ax)
        save_figure(fig, path)

    def check(path: Path) -> None:
        from rockyade.figures.canvas import new_figure, save_figure
        from rockyade.figures.wall_assessment import plot_capacity

        fig, ax = new_figure(path, figsize=(7.2, 6.4), layout="constrained")
        plot_capacity(a, ax)
        save_figure(fig, path)

    def fragility(path: Path) -> None:
        from rockyade.figures.canvas import new_figure, save_figure
        from rockyade.figures.wall_assessment import assessment_marks, plot_fragility

        assert a.dynamic is not None
        fig, ax = new_figure(path, figsize=(7.2, 6.2), layout="constrained")
        plot_fragility(a.dynamic, ax, marks=assessment_marks(a))
        save_figure(fig, path)

    def selection(path: Path) -> None:
        _draw_selection(a, path)

    return {
        FIGURE_SPECTRUM: spectrum,
        FIGURE_MECHANISM: mechanism,
        FIGURE_CHECK: check,
        FIGURE_FRAGILITY: fragility,
        FIGURE_SELECTION: selection,
    }


def _draw_selection(a: Assessment, path: Path) -> None:
    """The selected records as the dynamics read them (each scaled by its factor): their 5 % spectra,
    their mean, the site's spectrum and the band of NTC 2018 3.2.3.6 (:mod:`rockyade.figures.record_selection`)."""
    from rockyade.figures.record_selection import plot_selection
    from rockyade.motion.selection import BAND_ABOVE, BAND_BELOW
    from rockyade.motion.spectra import response_spectrum

    assert a.dynamic is not None
    motions = a.dynamic.plan.stripes.motions
    selection = (motions.selection if isinstance(motions, RecordFiles) else None) or {}
    t_range = tuple(selection.get("period_range_s") or (0.15, 2.0))
    records = [motions.record(i) for i in range(motions.count)]
    longest = min(r.duration_s for r in records)
    periods = np.geomspace(0.05, min(4.0, longest), 120)
    scaled = np.array([response_spectrum(r.accel_m_s2, r.dt_s, periods, 0.05)[1] for r in records])
    plot_selection(
        periods,
        a.site.spectrum.psa(periods),
        scaled,
        [motions.label(i) for i in range(motions.count)],
        (BAND_BELOW, BAND_ABOVE),
        (float(t_range[0]), float(t_range[1])),
        path,
        title=f"{a.site.spectrum.label}; the selection {selection.get('selection', '')}",
    )


def write_report(folder: Path, a: Assessment, data: Mapping[str, Any], prov: Provenance) -> list[str]:
    """Write the report of ``a`` into ``folder`` as one set (module docstring); the files written.

    Parameters
    ----------
    folder
        The report's folder (made if missing; refused when it holds other files).
    a
        The assessment (its figures are drawn from it).
    data
        What ``assess.json`` holds, the page's numbers.
    prov
        The inputs' sources and the versions.
    """
    from rockyade.io.atomic import write_text
    from rockyade.io.folders import output_folder
    from rockyade.io.locking import output_lock
    from rockyade.io.resultset import replacing_set

    check_report_folder(folder)
    page = report_page(data, prov)
    drawers = _figures(a, Path(prov.scene).name)
    with output_folder(folder), output_lock(folder, "--report"):
        check_report_folder(folder)  # again under the lock: nothing came in meanwhile
        with replacing_set(folder, REPORT_SET, REPORT_LAST) as stage:
            images = {}
            for figure in page.figures:
                drawers[figure.name](stage / figure.name)
                images[figure.name] = (stage / figure.name).read_bytes()
            write_text(stage / REPORT_MD, render_markdown(page))
            write_text(stage / REPORT_HTML, render_html(page, images))
    return [f.name for f in page.figures] + [REPORT_MD, REPORT_HTML]


__all__ = [
    "REPORT_HTML",
    "REPORT_LAST",
    "REPORT_MD",
    "REPORT_SET",
    "check_report_folder",
    "provenance",
    "versions",
    "write_report",
]
