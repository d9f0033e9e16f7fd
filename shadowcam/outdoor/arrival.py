"""Per-pixel shadow-arrival time (seconds, sub-frame) from tracked edges.

Two estimators, combined:

* **edge crossing** (:func:`arrival_from_edges`): the tracked edge row of each
  column is a function of time; a pixel's arrival is when the edge passes its
  centre ``r + 0.5``, linear in time between the two frames whose edges
  straddle it. The sub-frame part comes from where the edge sits *spatially*
  (sub-pixel) in each frame.
* **coverage crossing** (:class:`CoverageCrossing`, streamed frame by frame):
  the first time the pixel's own lit fraction drops through 0.5, linear in
  time between the two frames around it. It covers what a single edge per
  column cannot represent (a second transition in a column, a sunlit tongue
  that sweeps sideways, pixels relit and shadowed again).

:func:`combine_arrivals` takes the edge crossing where the two agree within a
tolerance and the coverage crossing elsewhere, and gives each pixel a reason.

Offers
------
ARRIVAL_REASONS : reason code -> name (CF flag meanings).
arrival_from_edges : arrival time of every pixel from the per-frame edge rows.
CoverageCrossing : streaming first downward 0.5-crossing of per-pixel coverage.
combine_arrivals : the final arrival map and its reasons.
arrival_dataset : the arrival-time map over (row, col) with reasons.
arrival_map : the arrival dataset of a capture from its photometry and edges datasets.
"""

import numpy as np
import xarray as xr

from shadowcam._shared.validation import check_positive, check_same_shape
from shadowcam.io.frame_times import median_interval, time_to_frame

#: reason code -> meaning (stored as CF flag_values / flag_meanings)
ARRIVAL_REASONS = {
    0: "edge_crossing",
    1: "coverage_crossing",
    2: "never_shadowed",
    3: "shadowed_at_start",
    4: "sky",
}
REASON_CODE = {name: code for code, name in ARRIVAL_REASONS.items()}


def arrival_from_edges(edge_row, time_s, *, eligible):
    """Arrival time of each pixel from the per-frame edge rows.

    Parameters
    ----------
    edge_row : (T, W) ndarray
        Edge row per frame and column (pixel-edge coordinates; lit above);
        NaN where there is none.
    time_s : (T,) ndarray
        Frame times in seconds.
    eligible : (H, W) bool ndarray
        Pixels that may receive an arrival (lit in the first frame, not sky).

    Returns
    -------
    (H, W) float64 ndarray
        Seconds; NaN where the edge never passed the pixel centre.
    """
    edge = np.asarray(edge_row, dtype=np.float64)
    times = np.asarray(time_s, dtype=np.float64)
    eligible = np.asarray(eligible, dtype=bool)
    if edge.ndim != 2 or times.shape != (edge.shape[0],) or eligible.ndim != 2 or eligible.shape[1] != edge.shape[1]:
        raise ValueError(f"edge_row {edge.shape} must be (T, W), time_s {times.shape} (T,), eligible {eligible.shape} (H, W)")
    height = eligible.shape[0]
    centre = np.arange(height, dtype=np.float64)[:, None] + 0.5
    arrival = np.full(eligible.shape, np.nan)
    for k in range(1, edge.shape[0]):
        y0, y1 = edge[k - 1][None, :], edge[k][None, :]
        with np.errstate(invalid="ignore"):
            cross = (y0 > centre) & (y1 <= centre) & eligible & np.isnan(arrival)
        if not cross.any():
            continue
        frac = (y0 - centre) / np.where(y0 > y1, y0 - y1, 1.0)
        value = times[k - 1] + np.clip(frac, 0.0, 1.0) * (times[k] - times[k - 1])
        arrival[cross] = np.broadcast_to(value, arrival.shape)[cross]
    return arrival


class CoverageCrossing:
    """Streaming first downward crossing of coverage 0.5 per pixel.

    Parameters
    ----------
    shape : tuple of int
        ``(H, W)``.
    eligible : (H, W) bool ndarray
        Pixels that may receive an arrival.
    level : float, optional
        The coverage level whose crossing is the arrival (0.5 = half the
        footprint shadowed).
    confirm : bool, optional
        A crossing counts only if the next frame is still below `level`
        (a cloud or a noisy frame darkening a pixel for one frame is not an
        arrival); a crossing in the last interval is kept.

    Notes
    -----
    State is a few ``(H, W)`` arrays (previous coverage, pending and final
    arrival), so memory does not depend on the number of frames. Feed frames
    in time order with :meth:`update`; read :attr:`arrival_s`.
    """

    def __init__(self, shape, *, eligible, level=0.5, confirm=True):
        self.eligible = np.asarray(eligible, dtype=bool)
        if self.eligible.shape != tuple(shape):
            raise ValueError(f"eligible {self.eligible.shape} must have shape {tuple(shape)}")
        self.level = float(level)
        self.confirm = bool(confirm)
        self._arrival = np.full(tuple(shape), np.nan)
        self._pending = np.full(tuple(shape), np.nan)
        self._previous = None
        self._time = None

    @property
    def arrival_s(self):
        """(H, W) float64 ndarray: arrival seconds so far (NaN = none)."""
        return np.where(np.isnan(self._arrival), self._pending, self._arrival)

    def update(self, cover, time_s):
        """Add the coverage ``(H, W)`` of the next frame, taken at `time_s` seconds."""
        cover = np.asarray(cover)
        if cover.shape != self._arrival.shape:
            raise ValueError(f"cover {cover.shape} must have shape {self._arrival.shape}")
        if self._previous is not None:
            if time_s <= self._time:
                raise ValueError(f"time_s must increase: got {time_s} after {self._time}")
            with np.errstate(invalid="ignore"):
                below = cover < self.level
                pending = np.isfinite(self._pending)
                confirmed = pending & below
                self._arrival[confirmed] = self._pending[confirmed]
                self._pending[pending] = np.nan
                cross = (self._previous >= self.level) & below & self.eligible & np.isnan(self._arrival)
            # interpolate (float64) only where a crossing happened: few pixels per frame
            prev = self._previous[cross].astype(np.float64)
            curr = cover[cross].astype(np.float64)
            frac = (prev - self.level) / np.where(prev > curr, prev - curr, 1.0)
            value = self._time + np.clip(frac, 0.0, 1.0) * (time_s - self._time)
            (self._pending if self.confirm else self._arrival)[cross] = value
        self._previous = cover.copy()
        self._time = float(time_s)


def combine_arrivals(edge_s, coverage_s, *, tolerance_s, sky, lit_at_start):
    """Final arrival map and per-pixel reason.

    Parameters
    ----------
    edge_s, coverage_s : (H, W) ndarray
        Arrival from edge crossing and from coverage crossing (NaN = none).
    tolerance_s : float
        The edge crossing is kept where the two agree within this many seconds
        (or where only it exists); elsewhere the coverage crossing is used.
    sky, lit_at_start : (H, W) bool ndarray

    Returns
    -------
    arrival_s : (H, W) float64 ndarray
    reason : (H, W) uint8 ndarray
        Codes of :data:`ARRIVAL_REASONS`.
    """
    edge_s = np.asarray(edge_s, dtype=np.float64)
    coverage_s = np.asarray(coverage_s, dtype=np.float64)
    check_same_shape({"edge_s": edge_s, "coverage_s": coverage_s})
    with np.errstate(invalid="ignore"):
        agree = np.abs(edge_s - coverage_s) <= tolerance_s
    use_edge = np.isfinite(edge_s) & (agree | np.isnan(coverage_s))
    arrival = np.where(use_edge, edge_s, coverage_s)
    reason = np.full(edge_s.shape, REASON_CODE["coverage_crossing"], dtype=np.uint8)
    reason[use_edge] = REASON_CODE["edge_crossing"]
    reason[np.isnan(arrival)] = REASON_CODE["never_shadowed"]
    reason[~np.asarray(lit_at_start, dtype=bool)] = REASON_CODE["shadowed_at_start"]
    sky = np.asarray(sky, dtype=bool)
    reason[sky] = REASON_CODE["sky"]
    arrival[sky | ~np.asarray(lit_at_start, dtype=bool)] = np.nan
    return arrival, reason

def arrival_dataset(arrival_s, arrival_frame, reason, *, edge_arrival_s, coverage_arrival_s, interval_s):
    """Assemble the arrival map.

    Returns
    -------
    xarray.Dataset
        ``arrival_time_s``, ``arrival_frame``, ``reason`` (CF flags),
        ``edge_arrival_s``, ``coverage_arrival_s`` over ``(row, col)``;
        attr ``median_interval_s``.
    """
    cam = ("row", "col")
    codes = sorted(ARRIVAL_REASONS)
    data = {
        "arrival_time_s": (cam, np.asarray(arrival_s), {"units": "s", "long_name": "shadow arrival time since the first frame"}),
        "arrival_frame": (cam, np.asarray(arrival_frame), {"units": "frame", "long_name": "arrival as fractional frame (piecewise linear in time_s)"}),
        "reason": (cam, np.asarray(reason, np.uint8), {
            "long_name": "how the arrival was obtained, or why there is none",
            "flag_values": np.array(codes, np.uint8), "flag_meanings": " ".join(ARRIVAL_REASONS[c] for c in codes)}),
        "edge_arrival_s": (cam, np.asarray(edge_arrival_s), {"units": "s", "long_name": "arrival from the tracked edge crossing the pixel centre"}),
        "coverage_arrival_s": (cam, np.asarray(coverage_arrival_s), {"units": "s", "long_name": "arrival from the pixel's lit fraction crossing 0.5"}),
    }
    dataset = xr.Dataset(data)
    dataset.attrs["median_interval_s"] = float(interval_s)
    return dataset


def arrival_map(photometry, edges, *, tolerance_intervals=1.5):
    """The arrival-time map of a capture (edge crossing checked against coverage crossing).

    Parameters
    ----------
    photometry : xarray.Dataset
        First-pass result: ``sky`` and ``lit_at_start`` over ``(row, col)``.
    edges : xarray.Dataset
        Tracked edges: ``edge_row (time, col)``, ``coverage_arrival_s (row, col)``, coord ``time_s``.
    tolerance_intervals : float, keyword-only
        Largest disagreement between the edge and coverage crossings, in median
        capture intervals, for the edge crossing to be kept.

    Returns
    -------
    xarray.Dataset
        As :func:`arrival_dataset`; ``arrival_frame`` clamped to the sequence.
    """
    check_positive(tolerance_intervals, "tolerance_intervals")
    time_s = edges["time_s"].values
    interval = median_interval(time_s)
    sky = photometry["sky"].values.astype(bool)
    lit = photometry["lit_at_start"].values.astype(bool)
    edge_s = arrival_from_edges(edges["edge_row"].values, time_s, eligible=lit & ~sky)
    coverage_s = edges["coverage_arrival_s"].values
    arrival, reason = combine_arrivals(edge_s, coverage_s, sky=sky, lit_at_start=lit,
                                       tolerance_s=tolerance_intervals * interval)
    return arrival_dataset(arrival, time_to_frame(arrival, time_s, outside="clamp"), reason,
                           edge_arrival_s=edge_s, coverage_arrival_s=coverage_s, interval_s=interval)
