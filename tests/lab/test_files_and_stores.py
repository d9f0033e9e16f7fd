"""One shadow-time path: a RAW capture's DNG files and its frame store give the same times.

A small RGGB capture (14-bit DNG, shot and read noise) of a textured plane: in the top half
a thin wire's hard shadow (timed by ``edge_fit`` from each pixel's own mosaic site), in the
bottom half a thin wire under a sampled disc light (two lobes: a connected dip, timed at its
removed light's centroid). The files are timed straight from their mosaics
(:func:`shadowcam.lab.sweep_files.sweep_shadow_times_from_files`), the store from its
demosaiced frames (:func:`shadowcam.lab.shadow_time.shadow_time_of_stores`).
"""

import numpy as np
import pytest

from shadowcam.io.frame_store import iter_frame_chunks, open_frames, write_frames
from shadowcam.io.raw_writer import write_dng, write_tiff16
from shadowcam.lab.dip_classification import OK, SEVERAL_MINIMA, WIDE_DIP
from shadowcam.lab.dip_tracker import track_intervals, without_interval
from shadowcam.lab.shadow_time import shadow_time_of_stores, summary_shadow_times, track_sweep
from shadowcam.lab.site_signal import cfa_site_colours
from shadowcam.lab.sweep_files import sweep_shadow_times_from_files

SHAPE = (48, 64)
N_FRAMES = 64
BLACK, WHITE = 512, 2**14 - 1
#: the renderer's 4 x 4 disc samples projected on the sweep direction (tests/lab/test_connected_dips.py)
_A, _B = np.meshgrid((np.arange(4) + 0.5) / 4, (np.arange(4) + 0.5) / 4, indexing="ij")
DISC_OFFSETS = (np.sqrt(_A) * np.cos(2 * np.pi * _B)).ravel()


def _capture(wire_sweep, directory, *, electrons=40000.0, read_noise=4.0, seed=1):
    """Write the capture's DNG files; return their paths and the truth ``(H, W)``."""
    h, w = SHAPE
    thin, thin_truth = wire_sweep(shape=SHAPE, level=1.0, n_frames=N_FRAMES, px_per_frame=1.5, t0=5.0, tilt=0.3)
    disc_truth = 14.0 + (np.arange(w)[None] + 0.3 * np.arange(h)[:, None]) / 2.0
    disc, _ = wire_sweep(n_frames=N_FRAMES, shape=SHAPE, centres=[disc_truth + 5.0 * o for o in DISC_OFFSETS],
                         depth=[1.0 / DISC_OFFSETS.size] * DISC_OFFSETS.size, width=2.0, ramp=1.0, level=1.0)
    top = np.arange(h)[:, None] < h // 2
    unit = np.where(top, thin, disc)
    rng = np.random.default_rng(seed)
    colour = cfa_site_colours(SHAPE, "RGGB")
    texture = (0.3 + 0.6 * rng.random(SHAPE + (3,)))
    own = np.take_along_axis(texture, colour[..., None].astype(np.intp), axis=2)[..., 0]
    paths = []
    for k in range(N_FRAMES):
        signal = own * unit[k] * electrons
        dn = BLACK + (rng.poisson(signal) + rng.normal(0.0, read_noise, SHAPE)) * (WHITE - BLACK) / electrons
        raw = np.clip(np.round(dn), 0, WHITE).astype(np.uint16)
        paths.append(write_dng(directory / f"frame_{k:03d}.dng", raw, bit_depth=14, black_level=BLACK,
                               white_level=WHITE))
    return paths, np.where(top, thin_truth, disc_truth), top


@pytest.fixture(scope="module")
def capture(wire_sweep, tmp_path_factory):
    directory = tmp_path_factory.mktemp("files_and_stores")
    paths, truth, top = _capture(wire_sweep, directory)
    write_frames(paths, directory / "u.zarr", times_s=np.arange(N_FRAMES) * 0.1)
    return paths, open_frames(directory / "u.zarr"), truth, top


def _window_only(store):
    """The store's times from its tracked windows and dip interval alone: no support, no own site."""
    def blocks():
        return (block for _, block in iter_frame_chunks(store))

    summary, _, _ = track_sweep(blocks(), SHAPE)
    summary, interval = without_interval(summary, track_intervals(blocks(), summary))
    return summary_shadow_times(summary, interval=interval, cfa_pattern="RGGB")


def test_the_files_and_the_store_give_the_same_reasons_and_times(capture):
    paths, store, truth, top = capture
    files = sweep_shadow_times_from_files(paths, workers=2, block_frames=5)
    stores = shadow_time_of_stores({"u": store}, min_coverage=0.0).sel(sweep="u")
    np.testing.assert_array_equal(files["reason"], stores["reason"].values)
    np.testing.assert_array_equal(files["saturated"], stores["saturated"].values)
    # not bit for bit: the store's frames are OpenCV's bilinear demosaic (interpolated channels
    # rounded to 1/k DN, k = 65535 // white = 4) summed in float32, the files' signal is the exact
    # bilinear sum from the mosaic (lab.mosaic_signal). The signals differ by at most
    # 2 * 0.5 / (k * (white - black)) = 1.6e-5 of the white level per sample; over a dip edge
    # of at least 0.1 of the white level per frame a time moves by under 2e-4 frame
    for name in ("shadow_time", "entry_time", "exit_time", "interval_entry", "interval_exit"):
        np.testing.assert_allclose(files[name], stores[name].values, rtol=0, atol=2e-4, err_msg=name)
    for name in ("lit_level", "lit_image"):
        np.testing.assert_allclose(files[name], stores[name].values, rtol=0, atol=2e-5, err_msg=name)
    np.testing.assert_allclose(files["time_std"], stores["time_std"].values, rtol=1e-3, err_msg="time_std")

    # the own site kept by the tracking pass: its noise from exact sums, not float64 block sums
    # (~1e-9 relative), so a float32 output moves by at most one unit in the last place
    first_pass = sweep_shadow_times_from_files(paths, workers=2, block_frames=5, own_site_in_first_pass=True)
    for name, value in files.items():
        if np.asarray(value).dtype == np.float32:
            np.testing.assert_array_max_ulp(first_pass[name], value, maxulp=1)
        else:
            np.testing.assert_array_equal(first_pass[name], value, err_msg=name)

    window_only = _window_only(store)
    timed = files["reason"] == OK
    # the disc's two lobes: the window alone leaves them several minima or wide, both paths time
    # them as one connected dip
    lobes = np.isin(window_only["reason"], (SEVERAL_MINIMA, WIDE_DIP)) & ~top
    assert lobes.sum() > 0.8 * (~top).sum()
    assert timed[lobes].mean() > 0.95
    # the thin wire's pixels are timed from their own site (not the channel sum's times),
    # closer to the exact truth than the channel sum: the demosaic blends the neighbours'
    # sites, shadowed at their own times and weighted by the texture
    wire = timed & top & (window_only["reason"] == OK)
    assert wire.sum() > 0.95 * top.sum()
    assert np.mean(files["shadow_time"][wire] != window_only["shadow_time"][wire]) > 0.9
    own_error = np.percentile(np.abs(files["shadow_time"] - truth)[wire], 95)
    sum_error = np.percentile(np.abs(window_only["shadow_time"] - truth)[wire], 95)
    assert own_error < 0.05 < sum_error


def test_tiff_files_and_their_store_give_the_same_results_bit_for_bit(wire_sweep, tmp_path):
    # no mosaic: the files' frames and the store's are one decode, so every variable is equal
    frames, _ = wire_sweep(shape=(24, 32), n_frames=40, px_per_frame=2.0, t0=5.0, electrons=400.0, seed=2)
    paths = [write_tiff16(tmp_path / f"frame_{k:03d}.tif", np.round(np.clip(frame, 0, 1) * 65535).astype(np.uint16))
             for k, frame in enumerate(frames)]
    write_frames(paths, tmp_path / "u.zarr", times_s=np.arange(len(paths)) * 0.1)
    files = sweep_shadow_times_from_files(paths, workers=2, block_frames=7)
    stores = shadow_time_of_stores({"u": open_frames(tmp_path / "u.zarr")}, min_coverage=0.0).sel(sweep="u")
    assert (files["reason"] == OK).mean() > 0.9
    for name in stores.data_vars:
        np.testing.assert_array_equal(files[name], stores[name].values, err_msg=name, strict=True)
