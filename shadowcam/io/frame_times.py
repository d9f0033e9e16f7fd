"""Frame times of a time-lapse: the source preference order, intervals and gaps.

Time-lapse intervals are irregular (intervalometer jitter, slow card writes)
and frames get dropped; every outdoor stage therefore works in seconds, never
in frame indices. The manifest's ``timing: {source: auto}`` takes the times
from the first source that covers every file, in the order of
:data:`AUTO_ORDER` (see :func:`shadowcam.io.manifest.frame_times`).

Offers
------
AUTO_ORDER : preference order of ``timing.source: auto``.
auto_candidates : the concrete timing specs ``auto`` tries, in order.
median_interval : the median capture interval (the unit of the accuracy figures).
find_gaps : intervals much longer than the median (dropped frames, pauses).
time_to_frame : times -> fractional frame indices, piecewise linear in the frame times.
"""

import numpy as np

from shadowcam._shared.validation import check_in

#: sources tried by ``timing: {source: auto}``, best first
AUTO_ORDER = ("metadata", "filename", "sidecar")


def auto_candidates(timing):
    """Return the concrete timing specs that ``source: auto`` tries, in order.

    Parameters
    ----------
    timing : mapping
        ``{source: auto}`` plus optional ``regex`` (and ``rate_hz``) for file
        names and ``file`` / ``key`` for a sidecar.

    Returns
    -------
    list of dict
        ``{source: metadata}`` always; ``{source: filename, regex, [rate_hz]}``
        if a regex is given; ``{source: sidecar, file, key}`` if a file is given.
    """
    if timing.get("source") != "auto":
        raise ValueError(f"timing.source must be 'auto' here; got {timing.get('source')!r}")
    candidates = [{"source": "metadata"}]
    if "regex" in timing:
        candidates.append({k: timing[k] for k in ("regex", "rate_hz") if k in timing} | {"source": "filename"})
    if "file" in timing:
        candidates.append({"source": "sidecar", "file": timing["file"], "key": timing.get("key", "times_s")})
    return candidates


def median_interval(times_s):
    """Return the median of the positive frame intervals in seconds (times must increase)."""
    times = np.asarray(times_s, dtype=np.float64)
    if times.ndim != 1 or times.size < 2:
        raise ValueError(f"times_s must hold at least 2 frame times; got shape {times.shape}")
    steps = np.diff(times)
    if np.any(steps <= 0):
        raise ValueError("times_s must increase strictly (check the timing source and the file order)")
    return float(np.median(steps))


def find_gaps(times_s, *, factor=1.5):
    """Return the intervals longer than `factor` times the median.

    Parameters
    ----------
    times_s : (T,) array_like
    factor : float, optional

    Returns
    -------
    list of dict
        ``{"after_frame": k, "interval_s": t[k+1] - t[k], "missing_frames": n}``
        with ``n`` the estimated number of dropped frames.
    """
    times = np.asarray(times_s, dtype=np.float64)
    step = median_interval(times)
    intervals = np.diff(times)
    return [{"after_frame": int(k), "interval_s": float(intervals[k]),
             "missing_frames": int(round(intervals[k] / step)) - 1}
            for k in np.nonzero(intervals > factor * step)[0]]


#: what :func:`time_to_frame` gives for a finite time outside the frame times
OUTSIDE_BEHAVIOURS = ("clamp", "nan")


def time_to_frame(time_s, frame_times_s, *, outside):
    """Fractional frame index of `time_s`, piecewise linear in the frame times.

    The one time-to-frame convention of the library, used by the estimates and
    the ground truth alike.

    Parameters
    ----------
    time_s : array_like
        Times in seconds (any shape); NaN and infinite times give NaN.
    frame_times_s : (T,) array_like
        Increasing frame times in seconds.
    outside : {"clamp", "nan"}, keyword-only
        A finite time before the first / after the last frame gives frame
        ``0`` / ``T - 1`` (``"clamp"``) or NaN (``"nan"``).

    Returns
    -------
    float64 ndarray, shape of `time_s`
    """
    check_in(outside, "outside", OUTSIDE_BEHAVIOURS)
    frames = np.asarray(frame_times_s, dtype=np.float64)
    time = np.asarray(time_s, dtype=np.float64)
    beyond = np.nan if outside == "nan" else None
    out = np.interp(time, frames, np.arange(frames.size, dtype=np.float64), left=beyond, right=beyond)
    return np.where(np.isfinite(time), out, np.nan)
