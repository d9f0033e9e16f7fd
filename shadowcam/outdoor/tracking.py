"""Second streaming pass over an outdoor time-lapse: coverage, edges, crossings.

With the shifts, gains and per-pixel levels of the first pass
(:mod:`shadowcam.outdoor.normalise`), each frame becomes a coverage image
(lit fraction, :func:`shadowcam.outdoor.photometric.coverage`), from which a cloud's shade
measured over the frame by the first pass (:mod:`shadowcam.outdoor.shade_field`) and a passing
cloud's shade measured just above each column's last edge (on the rows the previous frame
left lit) are divided out (:mod:`shadowcam.outdoor.shade`); frame differencing against the
previous coverage gives the band where the edge moved (:mod:`shadowcam.outdoor.frame_difference`); the
edge of every column is located with sub-pixel precision
(:mod:`shadowcam.outdoor.edge_tracking`), preferring transitions in the band, then near
the column's most recent edge (tracking), and the dark episodes of every pixel are
accumulated (:class:`shadowcam.outdoor.episodes.ShadowEpisodes`), with each pixel's final
descent, whose penumbra ramp is fitted at the end (:mod:`shadowcam.outdoor.descent`). The lit level of each
pixel follows slow shading changes (the sun moves) while the pixel is fully lit and well
above the edge. Memory is a few ``(H, W)`` arrays, ``E`` episode slots and twice ``descent_frames``
float16 values per pixel (coverage and luminance) and the ``(T, W)`` edges.

Every step but the frame differencing's widening (``margin`` columns), the episodes'
neighbour count (one pixel each side), the ramps' neighbours' duration (three pixels) and the
registration shift (:func:`shadowcam.outdoor.translation.translate`, ``"cubic_Keys1981"``,
whose bits do not depend on where the frame is cut) works column by column,
so column strips of the frames can be tracked as separate jobs and merged
exactly (:mod:`shadowcam.outdoor.strips`).

Offers
------
PIXEL_KEYS : the per-pixel ``(row, col, ...)`` results.
EdgeTracker : the streaming pass; :meth:`update` per frame, :meth:`result`.
track_frames : run it over an iterable of frames.
"""

import numpy as np

from shadowcam.outdoor.clipping import CLIPPED_SHARE, OWN_SHARE, registered_clipped
from shadowcam.outdoor.descent import STATE_CODE, DescentBuffer, fit_descents
from shadowcam.outdoor.edge_tracking import column_edges
from shadowcam.outdoor.episodes import ShadowEpisodes
from shadowcam.outdoor.frame_difference import difference_band
from shadowcam.outdoor.photometric import coverage, luminance
from shadowcam.outdoor.shade import remove_shade, shade_above_edge
from shadowcam.outdoor.shade_field import interpolate_field
from shadowcam.outdoor.translation import translate


#: rows between the edge and the rows a passing shade is measured on (plus the edge's width)
SHADE_GAP = 4
#: per-pixel (row, col, ...) results of the pass
PIXEL_KEYS = ("coverage_arrival_s", "final_depth", "event_start_s", "event_end_s", "event_depth", "n_events",
              "ramp_centre_s", "ramp_duration_s", "ramp_sigma_s", "ramp_state")


class EdgeTracker:
    """Streaming coverage, frame differencing, edge tracking and coverage crossing.

    Parameters
    ----------
    photometry : mapping
        ``shift (T, 2)``, ``gain_lit (T,)``, ``gain_sky (T,)``, ``sky``,
        ``lit_at_start``, ``lit_level``, ``shadow_level`` ``(H, W)`` and, optionally,
        ``shadow_ratio`` (the result of :func:`shadowcam.outdoor.normalise.normalise_frames`):
        with it the final descents keep their exposure-normalised luminance too and the long
        ramps are timed by their half-level crossing (:mod:`shadowcam.outdoor.half_level`);
        optionally ``shade_field (T, By, Bx)`` with ``shade_rows``, ``shade_cols`` (the cloud's
        shade over the frame, :mod:`shadowcam.outdoor.shade_field`; block centres in the
        columns of the frames given), interpolated and divided out of the frame's coverage where
        below 1; without it, ``cloud_shade (T,)`` (a first pass written before the field) divided
        out uniformly.
    time_s : (T,) ndarray
        Frame times in seconds.
    half_window : int, optional
        Half window of the edge's area estimator (rows).
    min_drop, margin : float, int, optional
        Frame-differencing options (:func:`shadowcam.outdoor.frame_difference.difference_band`).
    max_step : float, optional
        Rows the edge may move between frames and still count as tracked.
    lit_update : float, optional
        Weight of the current frame in the running lit level (0 = fixed).
    update_distance : float, optional
        The lit level is updated only this many rows or more above the edge.
    count_cols : (2,) tuple of int, optional
        Columns ``[c0, c1)`` of the frames over which :attr:`band_count` (pixels in
        the band, per frame) and :attr:`valid_count` (valid pixels) are counted
        (default all): the exact partial sums of ``band_fraction`` for a column strip.
    edge_width_rows : float, optional
        Measured width of the shadow edge (:func:`shadowcam.outdoor.strips.edge_width`):
        the lit level is updated only `update_distance` rows beyond it, and a passing
        shade is measured that many rows further above the edge, so that neither takes
        the penumbra's own dimming (the real sun behind a far ridge: tens of rows) for a
        change of the lit level or for a cloud; and the ramps the sequence's end cut take
        their duration and shadow level from confident fits that many rows away.
    descent_frames : int, optional
        Frames of each pixel's final descent kept for the penumbra fit
        (:class:`shadowcam.outdoor.descent.DescentBuffer`; at least the penumbra's
        duration in frames plus a few frames of lit and shadowed level).
    max_sigma : float, optional
        Largest standard error of a fitted ramp centre, in median intervals
        (:func:`shadowcam.outdoor.descent.fit_descents`).
    white_level : float or None, optional
        Decoded value of the sensor's white level (:func:`shadowcam.outdoor.clipping.store_white_level`):
        a reading a clipped sample enters does not update the lit level, and a pixel whose own
        clipped sample reads below the level at or after its final crossing gets no time (ramp state
        ``clipped_crossing``). None: nothing is known to clip.
    """

    def __init__(self, photometry, time_s, *, half_window=3, min_drop=0.2, margin=2, max_step=3.0,
                 lit_update=0.3, update_distance=4.0, count_cols=None, edge_width_rows=0.0, descent_frames=128,
                 max_sigma=1.0, white_level=None):
        self.white_level = None if white_level is None else float(white_level)
        self.shift = np.asarray(photometry["shift"], dtype=np.float64)
        self.gain_lit = np.asarray(photometry["gain_lit"], dtype=np.float64)
        self.gain_sky = np.asarray(photometry["gain_sky"], dtype=np.float64)
        field = photometry.get("shade_field")
        if field is None:  # a first pass without the field: its per-frame shade, uniform over the frame
            uniform = photometry.get("cloud_shade")
            self.shade_field = None if uniform is None else np.asarray(uniform, dtype=np.float32)[:, None, None]
            self.shade_grid = (np.zeros(1), np.zeros(1))
        else:
            self.shade_field = np.asarray(field, dtype=np.float32)
            self.shade_grid = (np.asarray(photometry["shade_rows"], dtype=np.float64),
                               np.asarray(photometry["shade_cols"], dtype=np.float64))
        self.time_s = np.asarray(time_s, dtype=np.float64)
        n_frames = self.time_s.size
        if not (self.shift.shape == (n_frames, 2) and self.gain_lit.shape == self.gain_sky.shape == (n_frames,)):
            raise ValueError(
                f"photometry shift {self.shift.shape}, gain_lit {self.gain_lit.shape}, gain_sky "
                f"{self.gain_sky.shape} do not match time_s ({n_frames} frames)"
            )
        if not 0 <= lit_update <= 1:
            raise ValueError(f"lit_update must be in [0, 1]; got {lit_update}")
        self.valid = ~np.asarray(photometry["sky"], dtype=bool)
        self.lit_at_start = np.asarray(photometry["lit_at_start"], dtype=bool)
        self.lit_level = np.array(photometry["lit_level"], dtype=np.float32)
        self.shadow_level = np.asarray(photometry["shadow_level"], dtype=np.float32)
        height, width = self.valid.shape
        self.options = dict(half_window=half_window, max_step=max_step)
        self.band_options = dict(min_drop=min_drop, margin=margin)
        if not edge_width_rows >= 0:
            raise ValueError(f"edge_width_rows must be >= 0; got {edge_width_rows}")
        soft = float(np.ceil(edge_width_rows))
        self._edge_width = int(soft)
        self.lit_update, self.update_distance = float(lit_update), float(update_distance) + soft
        self._shade_gap = SHADE_GAP + int(soft)
        self.edge_row = np.full((n_frames, width), np.nan, dtype=np.float32)
        self.confidence = np.zeros((n_frames, width), dtype=np.float32)
        self.n_transitions = np.zeros((n_frames, width), dtype=np.int16)
        self.band_fraction = np.zeros(n_frames, dtype=np.float32)
        c0, c1 = (0, width) if count_cols is None else (int(c) for c in count_cols)
        if not 0 <= c0 < c1 <= width:
            raise ValueError(f"count_cols must be (c0, c1) with 0 <= c0 < c1 <= {width}; got {count_cols}")
        self._counted = np.s_[:, c0:c1]
        self.band_count = np.zeros(n_frames, dtype=np.int64)
        self.valid_count = int(self.valid[self._counted].sum())
        self.episodes = ShadowEpisodes((height, width), eligible=self.lit_at_start & self.valid)
        ratio = photometry.get("shadow_ratio")
        self.shadow_ratio = float(ratio) if ratio is not None and np.isfinite(ratio) else None
        self.descent = DescentBuffer((height, width), frames=descent_frames, luminance=self.shadow_ratio is not None)
        self.max_sigma = float(max_sigma)
        self._clipped_dark_s = np.full((height, width), -np.inf)  # last clipped sample below the level
        self._previous = None
        self._last_edge = np.full(width, np.nan, dtype=np.float32)  # most recent edge found per column
        self._k = 0
        self._centre = np.arange(height, dtype=np.float32)[:, None] + 0.5

    def update(self, frame):
        """Process the next frame ``(H, W, C)``."""
        k = self._k
        if k >= self.time_s.size:
            raise ValueError(f"more frames than frame times ({self.time_s.size})")
        luma = translate(luminance(frame), self.shift[k], method="cubic_Keys1981") / np.float32(self.gain_lit[k])
        shadow = self.shadow_level * np.float32(self.gain_sky[k] / self.gain_lit[k])
        cover = coverage(luma, lit_level=self.lit_level, shadow_level=shadow)
        clipped = None if self.white_level is None else registered_clipped(frame, self.shift[k],
                                                                           white_level=self.white_level)
        if self.shade_field is not None and (self.shade_field[k] < 1).any():  # a cloud's shade over the frame
            cover /= interpolate_field(self.shade_field[k], row_centres=self.shade_grid[0],
                                       col_centres=self.shade_grid[1], shape=cover.shape)
        if k:  # a passing cloud's shade at the edge (measured above the last edge found)
            # rows the previous frame left dark (its shade divided out) are in the ridge's shadow
            lit = self.lit_at_start & self.valid & (self._previous >= self.episodes.level)
            shade = shade_above_edge(cover, self._last_edge, valid=lit, gap=self._shade_gap)
            cover = remove_shade(cover, shade, self._last_edge, gap=self._shade_gap)
        band = None
        if self._previous is not None:
            band = difference_band(self._previous, cover, valid=self.valid, **self.band_options)
            self.band_fraction[k] = band[self.valid].mean() if self.valid.any() else 0.0
            self.band_count[k] = np.count_nonzero(band[self._counted] & self.valid[self._counted])
        self.edge_row[k], self.confidence[k], self.n_transitions[k] = column_edges(
            cover, valid=self.valid, band=band, previous=self._last_edge if k else None, **self.options)
        found = np.isfinite(self.edge_row[k])
        self._last_edge[found] = self.edge_row[k][found]
        self.episodes.update(cover, self.time_s[k])
        if clipped is not None:  # a clipped reading is a lower bound of the light: below the level, not dark
            self._clipped_dark_s[(clipped >= OWN_SHARE) & (cover < self.episodes.level)] = self.time_s[k]
        self.descent.update(cover, dark=self.episodes.dark & np.isfinite(self.episodes.start),
                            luminance=None if self.shadow_ratio is None else shadow + cover * (self.lit_level - shadow))
        if self.lit_update > 0:
            with np.errstate(invalid="ignore"):
                far = ~(self._centre > self.edge_row[k][None, :] - self.update_distance)
            update = self.lit_at_start & (cover > 0.9) & far
            if clipped is not None:  # a reading a clipped sample enters is no level
                update &= np.abs(clipped) < CLIPPED_SHARE
            blended = (1 - self.lit_update) * self.lit_level + self.lit_update * luma
            np.copyto(self.lit_level, blended, where=update)
        self._previous = cover
        self._k += 1

    def result(self):
        """Return the pass's results (see :func:`track_frames`)."""
        if self._k != self.time_s.size:
            raise ValueError(f"got {self._k} frames but {self.time_s.size} frame times")
        episodes = {"coverage_arrival_s" if key == "final_start_s" else key: value
                    for key, value in self.episodes.result().items()}
        ramps = fit_descents(self.descent, episodes["coverage_arrival_s"], self.time_s, max_sigma=self.max_sigma,
                             cut_rows=self._edge_width, shadow_ratio=self.shadow_ratio)
        # a sample read below the level on the clip at or after the final crossing: the light may
        # have been above it, the crossing later; neither the crossing nor the ramp's time stands
        with np.errstate(invalid="ignore"):
            hidden = self._clipped_dark_s >= episodes["coverage_arrival_s"]
        ramps["ramp_state"][hidden] = STATE_CODE["clipped_crossing"]
        ramps["ramp_centre_s"][hidden] = np.nan
        return {
            "edge_row": self.edge_row,
            "confidence": self.confidence,
            "n_transitions": self.n_transitions,
            "band_fraction": self.band_fraction,
            **episodes,
            **ramps,
        }


def track_frames(frames, photometry, time_s, **options):
    """Run :class:`EdgeTracker` over `frames`.

    Parameters
    ----------
    frames : iterable of (H, W, C) ndarray
        In time order.
    photometry : mapping
        See :class:`EdgeTracker`.
    time_s : (T,) ndarray
    **options
        Keyword options of :class:`EdgeTracker`.

    Returns
    -------
    dict
        ``edge_row (T, W)`` (pixel-edge rows, NaN = none), ``confidence (T, W)``,
        ``n_transitions (T, W)``, ``band_fraction (T,)`` (share of valid pixels in
        the frame-differencing band), ``coverage_arrival_s (H, W)`` (start of the final dark
        episode) and the earlier episodes: ``event_start_s``, ``event_end_s``, ``event_depth``
        ``(H, W, E)``, ``n_events (H, W)`` (:class:`shadowcam.outdoor.episodes.ShadowEpisodes`) and the
        fitted final descent: ``ramp_centre_s``, ``ramp_duration_s``, ``ramp_sigma_s``, ``ramp_state``
        ``(H, W)`` (:func:`shadowcam.outdoor.descent.fit_descents`).
    """
    tracker = EdgeTracker(photometry, time_s, **options)
    for frame in frames:
        tracker.update(frame)
    return tracker.result()
