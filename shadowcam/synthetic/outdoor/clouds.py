"""Cloud-shadow scenarios of a synthetic sunset: which clouds cross the view, when and how.

A cloud shadow dims the sun term of the points it covers for as long as it takes to drift
past them, then they relight: a transient shadow, unlike the ridge's, which stays. The
scenarios vary what a tracker could fit to one cloud model: size (a few pixels to a large
part of the cliff), speed (a few to some twenty frames over a point), border (Gaussian,
soft rim, hard rim), depth, number per sequence, and a cloud that crosses the ridge shadow's
edge while the edge moves, and a cloud over part or all of the lit cliff in the first frame.

Every cloud but ``drifting`` is placed from the ground truth of the view: it passes over a
point that the ridge shadow reaches well after the cloud has gone (so the cloud is seen on
the lit cliff, as a photographer would see it), or, for ``edge_crossing``, over a point the
ridge edge reaches while the cloud is there.

Offers
------
CLOUD_SCENARIOS : scenario names.
cloud_shadows : the clouds (start, drift, radius, depth, rim) of a scenario.
"""

import numpy as np

from shadowcam._shared.validation import check_in

#: the cloud of the original renders: a soft blob drifting from the valley over the cliff
#: during the whole sequence (``True`` in a manifest)
DRIFTING = {"depth": 0.5, "sigma_m": 150.0, "rim_m": None}
#: scenario -> clouds: radius (m), rim (m, None = Gaussian), depth, frames over a point,
#: and where it passes ("lit": on the lit cliff before the ridge shadow, "edge": across the edge)
_SCENARIOS = {
    "drifting": None,
    "small_fast_hard": [(60.0, 2.0, 0.7, 5.0, "lit")],
    "large_slow_soft": [(260.0, None, 0.6, 22.0, "lit")],
    "dozen_frames": [(110.0, 15.0, 0.65, 12.0, "lit")],
    "several": [(70.0, 3.0, 0.55, 7.0, "lit"), (150.0, 40.0, 0.75, 14.0, "lit"),
                (100.0, None, 0.5, 10.0, "lit")],
    "edge_crossing": [(120.0, 8.0, 0.7, 12.0, "edge")],
    # over part of the lit cliff in the first frame (the pass's reference), gone a few frames later
    # (radius: a third of the lit cliff's extent)
    "first_frame": [(None, 8.0, 0.65, 8.0, "first")],
    # over the whole lit cliff in the first frame (radius: the lit cliff's, with a margin)
    "first_frame_whole": [(None, 8.0, 0.65, 8.0, "first_whole")],
}
CLOUD_SCENARIOS = tuple(_SCENARIOS)


def _drifting(terrain, duration_s, seed):
    """Seeded straight drift from the valley over the cliff toward the plateau (+a), across a
    band of the view (b), during the whole sequence."""
    rng = np.random.default_rng([int(seed), 53])
    a0, b0 = -700.0, rng.uniform(-700.0, 100.0)
    va, vb = 1600.0 / duration_s, rng.uniform(-0.05, 0.05)
    start = terrain.to_xy(a0, b0)
    end = terrain.to_xy(a0 + va * duration_s, b0 + vb * duration_s)
    velocity = (np.asarray(end) - np.asarray(start)) / duration_s
    return dict(DRIFTING, start_xy=np.asarray(start, dtype=np.float64), velocity_xy=velocity)


def cloud_shadows(scenario, *, terrain, duration_s, points_xy, arrival_s, times_s, seed):
    """The clouds of a scenario.

    Parameters
    ----------
    scenario : str
        One of :data:`CLOUD_SCENARIOS`.
    terrain : shadowcam.synthetic.outdoor.terrain.Heightfield
    duration_s : float
    points_xy : (N, 2) ndarray
        Ground (x, y) of the pixel centres that see terrain (m).
    arrival_s : (N,) ndarray
        Their ridge-shadow arrival (s; +inf never shadowed, -inf shadowed at start).
    times_s : (K,) ndarray
        Frame times (s).
    seed : int

    Returns
    -------
    list of dict
        ``start_xy``, ``velocity_xy`` (m, m/s), ``sigma_m`` (radius), ``depth``, ``rim_m``
        (keywords of :func:`shadowcam.synthetic.outdoor.nuisance.cloud_transmittance`).
    """
    check_in(scenario, "scenario", CLOUD_SCENARIOS)
    if scenario == "drifting":
        return [_drifting(terrain, duration_s, seed)]
    points = np.asarray(points_xy, dtype=np.float64)
    arrival = np.asarray(arrival_s, dtype=np.float64)
    times = np.asarray(times_s, dtype=np.float64)
    interval = float(np.median(np.diff(times)))
    rng = np.random.default_rng([int(seed), 59, CLOUD_SCENARIOS.index(scenario)])
    clouds = []
    for k, (radius, rim, depth, frames_over, where) in enumerate(_SCENARIOS[scenario]):
        passage = frames_over * interval
        heading = rng.uniform(0.0, 2.0 * np.pi)
        # when the cloud is over its point: spread the clouds of a scenario over the sequence
        lo, hi = (0.1 + 0.25 * k) * times[-1], (0.3 + 0.25 * k) * times[-1]
        t0 = 0.0 if where.startswith("first") else rng.uniform(lo, hi)
        if where == "first_whole":
            # centred on the lit cliff, its core over every lit point at the first frame
            lit = np.isfinite(arrival) & (arrival > 0.0) | (arrival == np.inf)
            centre = points[lit].mean(axis=0)
            radius = 1.2 * float(np.sqrt(((points[lit] - centre) ** 2).sum(axis=1).max())) + 4.0 * rim
            velocity = 2.0 * radius / passage * np.array([np.cos(heading), np.sin(heading)])
            clouds.append({"start_xy": centre, "velocity_xy": velocity, "sigma_m": radius, "depth": depth,
                           "rim_m": rim})
            continue
        if where == "first":
            # over part of the lit cliff at the first frame: a third of its extent, centred on a
            # lit point half way out from its middle, moving further out (off the cliff)
            lit = np.isfinite(arrival) & (arrival > 0.0) | (arrival == np.inf)
            centre = points[lit].mean(axis=0)
            extent = float(np.sqrt(((points[lit] - centre) ** 2).sum(axis=1).max()))
            out = points[lit] - centre
            reach = np.sqrt((out ** 2).sum(axis=1))
            target = points[lit][np.argmin(np.abs(reach - 0.5 * extent))]
            radius = extent / 3.0
            outward = (target - centre) / max(float(np.hypot(*(target - centre))), 1e-9)
            clouds.append({"start_xy": target, "velocity_xy": 2.0 * radius / passage * outward, "sigma_m": radius,
                           "depth": depth, "rim_m": rim})
            continue
        speed = 2.0 * radius / passage
        velocity = speed * np.array([np.cos(heading), np.sin(heading)])
        if where == "lit":
            # lit at start, reached by the ridge shadow long after the cloud has passed
            ok = np.isfinite(arrival) & (arrival > t0 + passage + 10.0 * interval) | (arrival == np.inf)
        else:
            ok = np.abs(arrival - t0) < interval
        if not ok.any():
            raise ValueError(f"scenario {scenario!r}: no pixel fits cloud {k} at {t0:.0f} s; "
                             "use a longer sequence or another scenario")
        target = points[rng.choice(np.flatnonzero(ok))]
        clouds.append({"start_xy": target - velocity * t0, "velocity_xy": velocity, "sigma_m": radius,
                       "depth": depth, "rim_m": rim})
    return clouds
