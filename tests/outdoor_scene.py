"""Seeded synthetic outdoor time-lapse with exact ground truth (test helper, not a test module).

A textured cliff (H x W) with a sky band at the top; a straight shadow edge
``y(t, c) = y0 - speed * t / interval + slope * (c + 0.5 - W / 2)`` (pixel-edge
rows; lit above) climbs it. Pixels are box-filtered (``ss x ss`` sub-samples),
lit radiance = albedo * (sun(t) + sky(t) * ambient), shadowed = albedo * sky(t) * ambient;
then exposure gain, a sub-pixel shake (cubic resampling), Poisson-Gaussian noise.
The exact arrival time of a pixel centre is where the edge passes ``r + 0.5``.

Offers
------
make_timelapse : frames, times and the exact ground truth.
"""

import numpy as np

from shadowcam.outdoor.translation import translate


def make_timelapse(*, height=64, width=64, n_frames=40, interval=60.0, speed=0.5, slope=0.15, y0=50.0,
                   sky_rows=6, seed=0, shake=0.0, noise=False, gain_steps=False, jitter=0.0, drop=(),
                   sun_fade=0.0, ss=8):
    """Return a dict with ``frames (T, H, W, 3)`` float32, ``time_s``, ``arrival_s (H, W)``
    (NaN where the edge never passes or sky), ``edge_row (T, W)``, ``shift (T, 2)``,
    ``gain (T,)``, ``sky (H, W)``, ``interval``, ``lit_at_start (H, W)``."""
    rng = np.random.default_rng(seed)
    nominal = np.arange(n_frames + len(drop))
    keep = np.array([k not in set(drop) for k in nominal])
    time_s = (nominal * interval + rng.uniform(-jitter, jitter, nominal.size) * interval)[keep]
    time_s -= time_s[0]
    albedo = 0.5 + 0.3 * rng.random((height, width, 1)) * np.array([1.0, 0.9, 0.7])
    albedo = albedo.astype(np.float64)
    sky = np.zeros((height, width), bool)
    sky[:sky_rows] = True
    ambient = 0.1
    cols = np.arange(width) + 0.5
    offs = (np.arange(ss) + 0.5) / ss
    sub_r = (np.arange(height)[:, None] + offs[None, :]).ravel()  # H*ss sub-rows
    sub_c = (np.arange(width)[:, None] + offs[None, :]).ravel()

    def edge_at(t):
        return y0 - speed * t / interval + slope * (sub_c - width / 2)

    frames, edges, shifts, gains = [], [], [], []
    gain = 1.0
    for k, t in enumerate(time_s):
        lit = (sub_r[:, None] < edge_at(t)[None, :]).astype(np.float64)
        cover = lit.reshape(height, ss, width, ss).mean(axis=(1, 3))
        sun = 1.0 - sun_fade * t / max(time_s[-1], 1.0)
        skyl = 1.0 - 0.5 * sun_fade * t / max(time_s[-1], 1.0)
        radiance = albedo * (sun * cover[..., None] + skyl * ambient)
        radiance[sky] = np.array([0.25, 0.3, 0.45]) * skyl
        if gain_steps and k and k % 7 == 0:
            gain *= 2 ** (1 / 3)
        image = (radiance * gain * 0.5).astype(np.float32)
        shift = rng.uniform(-shake, shake, 2) if (shake and k) else np.zeros(2)
        if shake and k:
            image = translate(image, -shift, method="opencv_cubic")  # content moves by +shift
        if noise:
            electrons = np.clip(image, 0, None) * 15000.0
            image = ((rng.poisson(electrons) + rng.normal(0, 4, image.shape)) / 15000.0).astype(np.float32)
        frames.append(image)
        edges.append(y0 - speed * t / interval + slope * (cols - width / 2))
        shifts.append(shift)
        gains.append(gain)
    centre = np.arange(height)[:, None] + 0.5
    line = y0 + slope * (cols[None, :] - width / 2)
    arrival = (line - centre) * interval / speed  # y(t) = centre
    lit_at_start = (centre < line) & ~sky
    arrival = np.where(lit_at_start & (arrival <= time_s[-1]), arrival, np.nan)
    return {"frames": np.array(frames), "time_s": time_s, "arrival_s": arrival, "edge_row": np.array(edges),
            "shift": np.array(shifts), "gain": np.array(gains), "sky": sky, "interval": float(interval),
            "lit_at_start": lit_at_start}
