"""Drawings of assemblies: at rest with names, snapshots and animations of real runs."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from PIL import Image

from rockyade.cli import main
from rockyade.errors import InputError
from rockyade.figures.assembly import (
    animate,
    animation_times,
    animation_writer_for,
    draw_assembly,
    drawn_names,
    moving_polygons,
    sample_index,
    write_snapshots,
)
from rockyade.result import Result
from rockyade.run_meta import RunMeta
from rockyade.scene import scene_from_dict
from rockyade.scene.generators import arch, rocking_frame, stack, wall, write_scene
from rockyade.scene.placement import placed_blocks, rotation_matrix
from rockyade.solvers import make_solver

from .conftest import EXAMPLES


def _png_size(path) -> tuple[int, int]:
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    with Image.open(path) as im:
        return im.size


def _rocking_result(scene, theta: np.ndarray, t: np.ndarray, pivot_block: str) -> Result:
    """A Result in which ``pivot_block`` rocks rigidly about its left base corner (others at rest)."""
    placed = {b.name: b for b in placed_blocks(scene)}
    names = [b.name for b in scene.blocks]
    data: dict[str, np.ndarray] = {"t_s": t, "ag_m_s2": np.zeros_like(t)}
    for name in names:
        b = placed[name]
        c = np.asarray(b.centroid_m)
        if name == pivot_block:
            pivot = b.vertices_m[np.lexsort((b.vertices_m[:, 0], b.vertices_m[:, 1]))[0]]
            moved = np.array([rotation_matrix(a) @ (c - pivot) + pivot for a in theta])
            data[f"{name}_theta_rad"], data[f"{name}_x_m"], data[f"{name}_y_m"] = theta, *(moved - c).T
        else:
            data[f"{name}_theta_rad"] = data[f"{name}_x_m"] = data[f"{name}_y_m"] = np.zeros_like(t)
    return Result(pd.DataFrame(data), RunMeta(status="completed", blocks=tuple(names), solver="synthetic"))


@pytest.mark.slow
def test_draw_writes_a_png_with_names_and_counts_the_names_left_out(tmp_path):
    small = scene_from_dict(wall(courses=3, units_per_course=4, openings=[(0.4, 0.0, 0.4, 0.2)]))
    _, ax = draw_assembly(small, tmp_path / "wall.png")
    assert sorted(drawn_names(ax)) == sorted(b.name for b in small.blocks)
    width, height = _png_size(tmp_path / "wall.png")
    assert width > 800 and 0.3 < height / width < 0.8  # a wide wall gives a wide figure
    big = scene_from_dict(wall(courses=40, units_per_course=25))  # 1,020 blocks: names too small to read
    _, ax = draw_assembly(big, tmp_path / "big.png")
    assert drawn_names(ax) == [] and "names too small to print" in ax.get_title()
    _, ax = draw_assembly(big, tmp_path / "big_nolabels.png", labels=False)
    assert drawn_names(ax) == [] and "too small" not in ax.get_title()
    fixed = scene_from_dict(arch(voussoirs=7, piers="fixed"))
    _, ax = draw_assembly(fixed, tmp_path / "arch.png")
    assert len(drawn_names(ax)) == len(fixed.blocks)
    _png_size(tmp_path / "arch.png")


def test_moving_polygon_rotates_about_the_pivot_and_keeps_the_block_rigid():
    scene = scene_from_dict(stack(widths_m=[0.4, 0.3], heights_m=[1.0, 0.8]))
    t = np.linspace(0.0, 1.0, 11)
    theta = 0.2 * np.sin(math.pi * t)
    result = _rocking_result(scene, theta, t, "b01")
    placed = placed_blocks(scene)
    k = 5  # theta = 0.2 rad
    moved = moving_polygons(placed, result, k)
    rest = placed[0].vertices_m
    # the pivot corner stays, the others turn by theta about it; edge lengths are kept
    np.testing.assert_allclose(moved[0][0], rest[0], atol=1e-12)
    expected = (rest - rest[0]) @ rotation_matrix(0.2).T + rest[0]
    np.testing.assert_allclose(moved[0], expected, atol=1e-12)
    np.testing.assert_allclose(moved[1], placed[1].vertices_m, atol=0.0)
    # magnified display: every vertex's displacement x3; the pivot stays where it is (the
    # block does not leave its support, as R(3 theta)(v - c) + c + 3 (x, y) made it do)
    big = moving_polygons(placed, result, k, scale=3.0)[0]
    np.testing.assert_allclose(big, rest + 3.0 * (expected - rest), atol=1e-12)
    np.testing.assert_allclose(big[0], rest[0], atol=1e-12)


def test_sample_index_refuses_times_outside_the_run():
    scene = scene_from_dict(stack(widths_m=[0.3], heights_m=1.0))
    t = np.arange(0.0, 1.0001, 0.01)
    result = _rocking_result(scene, 0.01 * t, t, "b01")
    assert sample_index(result, 0.504) == 50
    with pytest.raises(InputError, match="outside"):
        sample_index(result, 1.5)


@pytest.mark.slow
def test_snapshots_and_animation_of_a_real_reference_run(tmp_path):
    scene = scene_from_dict(
        rocking_frame(
            duration_s=0.6,
            sample_dt_s=0.01,
            motion={"type": "pulse", "shape": "sine", "amplitude_g": 0.4, "period_s": 0.4},
        )
    )
    result = make_solver("reference").run(scene)
    assert result.status == "completed"
    peak = max(np.abs(result.series("theta_rad", b)).max() for b in ("column_left", "column_right"))
    assert peak > 0.01  # the frame rocks: the snapshots show something
    grid = write_snapshots(scene, result, [0.2, 0.4, 0.6], tmp_path / "snap.png")
    assert grid == [tmp_path / "snap.png"]
    width, height = _png_size(grid[0])
    assert width > height  # three panels side by side
    files = write_snapshots(scene, result, [0.3, 0.5], tmp_path / "one.png", layout="files", scale=2.0)
    assert [p.name for p in files] == ["one_t0.300s.png", "one_t0.500s.png"]
    _, _, anim = animate(scene, result, tmp_path / "run.gif", fps=10.0)
    assert len(animation_times(result, 10.0, 1.0)) == 7 and anim is not None
    with Image.open(tmp_path / "run.gif") as im:
        assert im.n_frames == 7
        first = np.asarray(im.convert("RGB")).copy()
        im.seek(4)
        later = np.asarray(im.convert("RGB"))
    assert np.abs(first.astype(int) - later.astype(int)).sum() > 0  # the frames differ: the frame moves


def test_mp4_needs_ffmpeg_and_other_suffixes_are_refused(tmp_path):
    from matplotlib import animation

    if animation.writers.is_available("ffmpeg"):
        assert animation_writer_for(tmp_path / "a.mp4", 10) is not None
    else:
        with pytest.raises(InputError, match="ffmpeg"):
            animation_writer_for(tmp_path / "a.mp4", 10)
    with pytest.raises(InputError, match=r"\.gif"):
        animation_writer_for(tmp_path / "a.avi", 10)


@pytest.mark.slow
def test_run_and_draw_commands_write_snapshots_from_relative_paths(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    scene = stack(
        widths_m=[0.25],
        heights_m=1.0,
        layout="column",
        duration_s=1.0,
        sample_dt_s=0.005,
        motion={"type": "pulse", "shape": "sine", "amplitude_g": 0.3, "period_s": 0.5},
    )
    write_scene(tmp_path / "block.toml", scene)
    (tmp_path / "out").mkdir()
    monkeypatch.chdir(tmp_path / "out")
    code = main(
        [
            "run",
            "../block.toml",
            "--out",
            "runs/r.csv",
            "--snapshots",
            "0.25,0.5,2.0",
            "--animation",
            "runs/r.gif",
            "--fps",
            "4",
        ]
    )
    assert code == 0
    out = capsys.readouterr().out
    assert "snapshot at t = 2 s skipped" in out
    assert "wrote runs/r_snapshots.png" in out and "wrote runs/r.gif (5 frames)" in out
    _png_size(tmp_path / "out/runs/r_snapshots.png")
    assert (
        main(
            [
                "draw",
                "../block.toml",
                "--out",
                "pics/block.png",
                "--result",
                "runs/r.csv",
                "--snapshots",
                "0.5",
                "--snapshot-layout",
                "files",
            ]
        )
        == 0
    )
    assert (tmp_path / "out/pics/block.png").is_file()
    assert (tmp_path / "out/pics/block_snapshots_t0.500s.png").is_file()
    capsys.readouterr()
    assert main(["run", "../block.toml", "--snapshots", "0.5,x"]) == 2
    assert "--snapshots" in capsys.readouterr().err
    assert main(["draw", "../block.toml", "--out", "p.png", "--snapshots", "0.5"]) == 2
    assert "--result: is required" in capsys.readouterr().err
    assert main(["run", "../block.toml", "--animation", "r.avi"]) == 2


def test_draw_refuses_a_result_of_another_scene_before_writing(tmp_path, capsys):
    frame = EXAMPLES / "assemblies/frame.toml"
    single = tmp_path / "single.csv"
    assert main(["run", str(EXAMPLES / "specimen1_free.toml"), "--solver", "housner", "--out", str(single)]) == 0
    out = tmp_path / "drawn" / "frame.png"
    code = main(["draw", str(frame), "--out", str(out), "--result", str(single), "--snapshots", "0.5"])
    assert code == 2 and "no history of the scene's block(s) column_left" in capsys.readouterr().err
    assert not out.exists() and not out.parent.exists()
