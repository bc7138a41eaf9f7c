"""YADE shows collapses: a collapsing arch ends overturned with its history, and a failed run
keeps what it recorded, marked partial, never read as a completed run."""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest

from rockyade.calibration.model_stage import calibrated_model
from rockyade.motion.spec import parse_motion
from rockyade.result import Result
from rockyade.scene import load_scene
from rockyade.solvers import run
from rockyade.yade import backend as yade_backend

from .conftest import EXAMPLES
from .limit_scenes import arch_scene
from .processes import require_yade
from .test_pushover import twice_eq7_step

pytestmark = pytest.mark.yade


def test_a_collapsing_arch_ends_overturned_in_yade_as_in_the_reference_dem():
    """A 20-voussoir arch of t/R 0.10 (below its static limit 0.1073), dropped: YADE's run stops
    at a deep sphere-polyhedron overlap after the collapse has begun and keeps its history; the
    first landing is within 3 % of the reference DEM's (measured 0.636 s against 0.6363 s). The
    overlap comes at 0.788 s: a window of 1 s holds it (1.5 s gave the same Result, sample for
    sample, after simulating 0.7 s more that the backend dropped). Both DEMs step at twice
    Eq 7's time step (``time_step_frac`` 0.2, half YADE's cost): first landings 0.634 s
    against 0.6354 s, the overlap still at 0.788 s."""
    require_yade()
    scene = arch_scene(0.10, 20).with_changes(motion=parse_motion({"type": "rest"}), duration_s=1.0)
    scene = twice_eq7_step(scene)
    reference = run(scene, "reference")
    yade = run(scene, "yade")
    assert reference.meta.status == "overturned"
    assert yade.meta.status == "overturned", yade.meta.failure_reason
    assert yade.meta.overturn_time_s == pytest.approx(reference.meta.overturn_time_s, rel=0.03)
    assert len(yade.frame) > 100 and np.all(np.isfinite(yade.frame["t_s"]))
    assert yade.t[-1] >= yade.meta.overturn_time_s - yade.meta.sample_dt_s


def test_a_failed_yade_run_keeps_its_samples_marked_partial(tmp_path):
    """A real YADE output whose driver said it failed half-way (a blow-up it detected): the
    Result has status failed, partial true and the samples before the failure; written and
    read back it is still failed, and a batch's --resume does not take it for done."""
    require_yade()
    model = calibrated_model(load_scene(EXAMPLES / "specimen1_free.toml"))
    good = yade_backend.run_model(model, workdir=tmp_path, name="ok")
    assert good.ok
    npz = tmp_path / "ok.yade.npz"
    with np.load(npz, allow_pickle=False) as data:
        arrays = {k: data[k] for k in data.files if k != "meta"}
        meta = json.loads(str(data["meta"]))
    half = meta["n_filled"] // 2
    meta.update(status="failed", stop_time_s=half * model.sample_dt_s, n_filled=half)
    with open(npz, "wb") as fh:
        np.savez(fh, **{k: v[:half] for k, v in arrays.items()}, meta=np.array(json.dumps(meta)))
    parsed = yade_backend._parse(model, npz, None, tmp_path / "ok.yade.log", 1.0, None)
    assert parsed.status == "failed" and not parsed.ok
    assert parsed.meta.partial is True and parsed.meta.partial_samples == half
    assert "numerical instability" in parsed.meta.failure_reason
    assert len(parsed.frame) == half
    np.testing.assert_array_equal(parsed.series("theta_rad"), good.series("theta_rad")[:half])
    out = tmp_path / "failed.csv"
    parsed.write(out)
    back = Result.read(out)
    assert back.status == "failed" and back.meta.partial is True and len(back.frame) == half

    from rockyade.batch import summary

    runs = tmp_path / "study" / "runs"
    runs.mkdir(parents=True)
    name = summary.run_name(model.scene_hash, "yade")
    parsed.write(runs / f"{name}.csv", {"summary": {"status": "failed"}})

    task = SimpleNamespace(
        name=name,
        scene_hash=model.scene_hash,
        index=0,
        labels={},
        solver=SimpleNamespace(name="yade"),
    )
    assert summary.completed_row(task, runs) is None
