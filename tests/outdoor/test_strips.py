"""Column strips of the edge-tracking pass equal the single job bit for bit.

A seeded synthetic time-lapse with camera shake (up to 2.5 px, so the halo has
to cover the shift resampling) and the shared dev_ridge capture are tracked in
one job and in 2 and 3 column strips (each strip fed only its window's
columns, as the workflow's jobs read them); the merged result must be
identical, including the whole-frame ``band_fraction``. A halo too narrow for
the shake must be caught by the merge, not give silently different edges.
"""

from pathlib import Path

import numpy as np
import pytest

from shadowcam.outdoor.normalise import normalise_frames
from shadowcam.outdoor.strips import merge_strips, strip_bounds, strip_halo, strip_window, track_strip
from shadowcam.outdoor.tracking import track_frames

REPO = Path(__file__).resolve().parents[2]


def _assert_identical(merged, single):
    assert merged.keys() == single.keys()
    for key, value in single.items():
        assert merged[key].dtype == value.dtype, key
        assert np.array_equal(merged[key], value, equal_nan=True), key


def _strips(frames, photometry, time_s, n_strips, **options):
    width = frames.shape[2]
    halo = strip_halo(photometry["shift"], **options)
    out = []
    for cols in strip_bounds(width, n_strips):
        a, b = strip_window(cols, halo, width)
        out.append(track_strip((f[:, a:b] for f in frames), photometry, time_s, cols=cols, halo=halo))
    return out


@pytest.fixture(scope="module")
def shaken(make_timelapse):
    scene = make_timelapse(width=70, n_frames=30, shake=2.5, noise=True, gain_steps=True, slope=0.3, seed=5)
    photometry = normalise_frames(iter(scene["frames"]))
    assert np.abs(photometry["shift"][:, 1]).max() > 1.5  # the halo matters
    return scene, photometry, track_frames(iter(scene["frames"]), photometry, scene["time_s"])


@pytest.mark.parametrize("n_strips", [2, 3])
def test_strips_of_a_shaken_scene_equal_the_single_job(shaken, n_strips):
    scene, photometry, single = shaken
    assert np.isfinite(single["edge_row"]).mean() > 0.9 and single["band_fraction"].max() > 0
    merged = merge_strips(_strips(scene["frames"], photometry, scene["time_s"], n_strips, guard=0))
    _assert_identical(merged, single)


def test_strips_accept_whole_frames_and_any_order(shaken):
    scene, photometry, single = shaken
    strips = [track_strip(iter(scene["frames"]), photometry, scene["time_s"], cols=cols)
              for cols in strip_bounds(70, 3)]
    _assert_identical(merge_strips(strips[::-1]), single)


def test_a_halo_too_narrow_for_the_shake_is_refused(shaken):
    scene, photometry, _ = shaken
    strips = [track_strip(iter(scene["frames"]), photometry, scene["time_s"], cols=cols, halo=1)
              for cols in strip_bounds(70, 2)]
    with pytest.raises(ValueError, match="halo"):
        merge_strips(strips)


def test_strip_layout_is_validated(shaken):
    scene, photometry, _ = shaken
    assert strip_bounds(70, 3) == [(0, 23), (23, 47), (47, 70)]
    # ceil(1.4) + 2 + 2 + the ramp fit's neighbours (3)
    assert strip_halo(np.array([[0.0, 0.2], [3.0, -1.4]]), margin=2, guard=0) == 9
    assert strip_window((0, 23), 6, 70) == (0, 29) and strip_window((47, 70), 6, 70) == (41, 70)
    with pytest.raises(ValueError, match="n_strips"):
        strip_bounds(70, 0)
    strips = [track_strip(iter(scene["frames"]), photometry, scene["time_s"], cols=cols) for cols in ((0, 30), (40, 70))]
    with pytest.raises(ValueError, match="tile"):
        merge_strips(strips)
    with pytest.raises(ValueError, match="frames"):
        track_strip((f[:, :10] for f in scene["frames"]), photometry, scene["time_s"], cols=(30, 40))


@pytest.mark.usefixtures("shared_data")  # the repository manifest reads the shared dev data
def test_strips_of_dev_ridge_equal_the_single_job():
    from shadowcam.io.decode import iter_frames
    from shadowcam.io.manifest import load_manifest

    sweep = load_manifest(REPO / "data_manifest" / "dev_ridge.yaml")["sweeps"]["timelapse"]
    frames = np.stack([image for _, image, _ in iter_frames(sweep["paths"])])
    time_s = np.asarray(sweep["times_s"])
    photometry = normalise_frames(iter(frames))
    single = track_frames(iter(frames), photometry, time_s)
    assert np.isfinite(single["edge_row"]).sum() > 20000
    for n_strips in (2, 3):
        _assert_identical(merge_strips(_strips(frames, photometry, time_s, n_strips, guard=0)), single)


@pytest.mark.slow  # runs the workflow (Snakemake) on dev_ridge
def test_workflow_strips_give_the_same_edges_nc_as_one_job(tmp_path, shared_data, snakemake, workflow_copy):
    import xarray as xr
    import yaml

    workdir = workflow_copy(tmp_path / "wf")
    manifest = yaml.safe_load((REPO / "data_manifest" / "dev_ridge.yaml").read_text())
    manifest["root"] = str(shared_data / "outdoor-dev" / "dev_ridge")
    (workdir / "data_manifest" / "dev_ridge.yaml").write_text(yaml.safe_dump(manifest))
    edges = workdir / "results" / "dev_ridge" / "outdoor" / "edges.nc"
    loaded = {}
    for count in (3, 1):  # 1 reruns track_edges alone (its strips input and params changed)
        (workdir / "strips.yaml").write_text(yaml.safe_dump({"outdoor": {"edge_strips": count}}))
        result = snakemake(["--cores", "2", str(edges.relative_to(workdir)), "--configfile", "config/config.yaml",
                            "strips.yaml", "--config", "datasets=[dev_ridge]"], workdir)
        assert result.returncode == 0, result.stdout[-3000:]
        with xr.open_dataset(edges, engine="h5netcdf") as dataset:
            loaded[count] = dataset.load()
    strip_logs = sorted((workdir / "logs" / "dev_ridge").glob("track_edges_strip*.log"))
    assert len(strip_logs) == 3 and not list(edges.parent.glob("edges.strips/*.npz"))  # temporary
    for name, variable in loaded[1].data_vars.items():
        assert np.array_equal(loaded[3][name].values, variable.values, equal_nan=variable.dtype.kind == "f"), name
