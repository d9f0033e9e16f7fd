"""The cast-shadow boundary test on demosaiced 12-bit RAW against an analytic straight edge.

A plane lit by the swept light carries a scene object's straight cast-shadow edge
(a vertical line at ``x_edge``, shadow on the left): pixel column ``c`` covers
``[c, c + 1)``, so its lit fraction is ``clip(c + 1 - x_edge, 0, 1)`` and the truth
counts it lit when its centre ``c + 0.5`` is. The frames are Bayer mosaics of the
scene (RGGB, 12 bit) demosaiced bilinearly, as the decode step does.
"""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from shadowcam.io.cfa import demosaic_bilinear
from shadowcam.lab.shadow_time import OK, sweep_shadow_times

SHAPE = (16, 24)
COLOUR = np.array([0.9, 0.7, 0.5])
WHITE = 4095
BLACK = 256


def _site_channel(shape, pattern="RGGB"):
    letters = np.array(list(pattern)).reshape(2, 2)
    index = np.vectorize("RGB".index)(letters)
    return np.tile(index, (shape[0] // 2, shape[1] // 2))


def _edge_sweep(wire_sweep, *, x_edge, shading, electrons=None, read_noise=6.0, seed=0):
    """Demosaiced frames of the edge scene under the sweep, and the exact truth.

    `shading` (W,) is the lit level of each column without the cast shadow. Returns
    ``frames (T, H, W, 3)`` in 0..1, the lit fraction per column, the truth's lit
    mask and its shadow times (NaN where unlit).
    """
    h, w = SHAPE
    unit, truth = wire_sweep(shape=SHAPE, level=1.0, n_frames=32, px_per_frame=1.0, t0=4.0, tilt=0.2)
    fraction = np.clip(np.arange(w) + 1.0 - x_edge, 0.0, 1.0)
    scene = (shading * fraction)[None, :, None] * COLOUR  # (1, W, 3) lit radiance per pixel
    site = _site_channel(SHAPE)
    rng = np.random.default_rng(seed)
    frames = np.empty(unit.shape + (3,), np.float32)
    for k, wire in enumerate(unit):
        mosaic = np.take_along_axis(np.broadcast_to(scene, (h, w, 3)), site[..., None], axis=2)[..., 0] * wire
        dn = mosaic * (WHITE - BLACK)
        if electrons is not None:  # electrons per unit signal, 1 DN per electron
            dn = rng.poisson(mosaic * electrons) + rng.normal(0.0, read_noise, mosaic.shape)
        raw = np.clip(np.round(BLACK + dn), 0, WHITE).astype(np.uint16)
        frames[k] = (demosaic_bilinear(raw, pattern="RGGB", max_value=WHITE) - BLACK) / (WHITE - BLACK)
    lit = np.broadcast_to(np.arange(w) + 0.5 > x_edge, SHAPE)
    return frames, fraction, lit, np.where(lit, truth, np.nan)


def _run(frames):
    return sweep_shadow_times([frames[i:i + 8] for i in range(0, len(frames), 8)], SHAPE,
                              cfa_pattern="RGGB", own_site=True)


def test_a_lit_pixel_beside_a_shadowed_same_colour_site_is_not_a_boundary(wire_sweep):
    # shading that rises 1.6x per pixel away from the shadow: a fully lit pixel's same-colour
    # site two columns further is 2.56x brighter, and the one two columns back is in the
    # shadow; the boundary does not cross its footprint, so it must keep its time
    x_edge = 8.4  # column 8 is 60 % lit (centre lit), column 9 fully lit
    shading = 0.02 * 1.6 ** np.clip(np.arange(SHAPE[1]) - x_edge, 0, None)
    frames, fraction, lit, truth = _edge_sweep(wire_sweep, x_edge=x_edge, shading=np.minimum(shading, 0.9))
    result = _run(frames)
    column = result["reason"][2:-2, 9]
    assert (column == OK).all()
    # its own dip (the bilinear demosaic mixes into its interpolated channels the dips of
    # neighbours 1.6x brighter, one frame apart: a bias of a quarter frame, not a wrong dip)
    err = np.abs(result["shadow_time"][2:-2, 9] - truth[2:-2, 9])
    assert err.max() < 0.5
    # no pixel in the cast shadow (centre unlit) gets a time
    assert not np.isfinite(result["shadow_time"][~lit]).any()


@pytest.mark.parametrize("lit_fraction", [0.2, 0.35, 0.65, 0.8])
def test_a_footprint_split_by_a_straight_edge_is_timed_when_its_centre_is_lit(wire_sweep, lit_fraction):
    # flat shading: the boundary column's lit fraction is its level over its same-colour
    # neighbours'; centre lit (truth) exactly when that fraction is over 1/2
    x_edge = 9.0 - lit_fraction
    frames, fraction, lit, truth = _edge_sweep(wire_sweep, x_edge=x_edge, shading=np.full(SHAPE[1], 0.6))
    assert fraction[8] == pytest.approx(lit_fraction)
    result = _run(frames)
    timed = np.isfinite(result["shadow_time"])
    inner = np.s_[2:-2]
    assert (timed[inner, 8] == (lit_fraction > 0.5)).all()
    assert timed[inner, 9:-1].all()
    assert not timed[~lit].any()


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**16), electrons=st.sampled_from([400.0, 1000.0, 3000.0]),
       lit_fraction=st.sampled_from([0.15, 0.3, 0.7, 0.85]))
def test_on_noisy_raw_cast_shadow_pixels_get_no_time_and_lit_ones_do(wire_sweep, seed, electrons, lit_fraction):
    # 12-bit RAW (black level 256, 1 DN per electron, read noise 6 DN) with 100 .. 1350
    # electrons at a fully lit site, 15 .. 1150 at the boundary's: its lit level is a mean
    # over ~28 lit frames, the darkness and lit-fraction tests allow for that mean's noise,
    # so the boundary column is decided by its lit fraction and the shadowed column beside
    # it gets no time. Inside the shadow (level 0 plus read noise) a time is pure noise,
    # given at the detection's false-alarm rate (1 % per pixel on its own)
    x_edge = 9.0 - lit_fraction
    frames, fraction, lit, truth = _edge_sweep(wire_sweep, x_edge=x_edge, shading=np.full(SHAPE[1], 0.5),
                                               electrons=electrons, seed=seed)
    result = _run(frames)
    timed = np.isfinite(result["shadow_time"])
    inner = np.s_[2:-2]
    assert (timed[inner, 8] == (lit_fraction > 0.5)).all()
    assert not timed[:, 7].any()
    assert timed[:, :7].sum() <= 3
    assert timed[inner, 9:-1].mean() >= 0.98
