"""Several intensity dips per pixel: the K deepest separated minima of a sweep.

Under several lights (paper Fig. 11) or a mask of several wires (paper Fig. 6) a
pixel's signal dips once per shadow. The minima are found in two streaming
passes over the frames, memory independent of their number; each block of frames
is split into row bands (:data:`BAND_PIXELS` pixels each), whose per-pixel work is
done band by band, so that the temporaries scale with a band, not the frame (only
the noise model pools every pixel; the result does not depend on the bands):

1. the :class:`~shadowcam.lab.dip_tracker.DipTracker` keeps each pixel's deepest
   smoothed local minima (its candidate list); the ``count`` deepest that lie
   more than ``half_window`` frames from each other are the pixel's minima
   (:func:`select_minima`), and one more (``extra_*``) tells whether the pixel
   has more dips than expected; a minimum between which and a deeper one the
   signal does not come back to the deeper dip's half depth is part of that dip
   (a flat or rippled bottom, overlapping shadows) and is dropped;
2. a second pass keeps the raw samples within ``2 * half_window`` frames of each minimum, and the level and
   noise of the frames more than ``half_window`` frames from every minimum (noise
   from first differences, so that a slowly varying lit level, as under a moving
   light, does not count). The pixels' noise estimates are pooled into the sensor's
   Poisson-Gaussian model (:mod:`shadowcam.lab.sensor_noise`), and a minimum counts
   only where its depth is significant against the noise of that depth (``depth_snr``).

Each minimum is then timed like a single dip: its window is cut where it meets
the next minimum's (each sample belongs to the nearest minimum), normalised by
the lit level interpolated between the window's ends (a straight line), and
passed to a timing method of :data:`shadowcam.lab.shadow_time_methods.SHADOW_TIME_METHODS`.

Offers
------
MINIMUM_REASONS : reason code -> meaning, per minimum.
BAND_PIXELS : pixels per row band of the per-pixel work.
row_bands : the row slices of those bands.
Minima : per-minimum times, depths, widths, uncertainties and reasons.
select_minima : the K deepest separated minima among candidate lists.
find_minima : two streaming passes over a sweep's frames -> :class:`Minima`.
"""

from dataclasses import dataclass, fields, is_dataclass, replace

import numpy as np
from scipy.special import ndtri

from shadowcam._shared.validation import check_array, check_in, check_positive
from shadowcam.lab.dip_tracker import DipSummary, DipTracker
from shadowcam.lab.sensor_noise import fit_noise_model, pixel_noise
from shadowcam.lab.dip_classification import _SMOOTHED_NOISE, detection_threshold
from shadowcam.lab.shadow_time_methods import SHADOW_TIME_METHODS
from shadowcam.lab.site_signal import SiteWindow, own_site_samples

#: reason code -> meaning, per minimum (0 = a reliable time)
MINIMUM_REASONS = {
    0: "ok",
    1: "missing",
    2: "low_contrast",
    3: "overlapping",
    4: "dip_at_sweep_end",
    5: "invalid_input",
    6: "wide_dip",
}
OK, MISSING, LOW_CONTRAST, OVERLAPPING, AT_END, INVALID, WIDE = range(7)


@dataclass
class Minima:
    """The minima of each pixel, ordered along the sweep (earliest first).

    Attributes
    ----------
    time : (K, H, W) float64
        Sub-frame time of each minimum; NaN where its reason is not ``ok``.
    estimate : (K, H, W) float64
        The timing method's value whatever the reason (NaN where missing).
    frame : (K, H, W) int64
        Frame of the smoothed minimum (-1 = missing).
    depth : (K, H, W) float64
        Lit level minus the lowest raw sample of the minimum's window.
    contrast : (K, H, W) float64
        ``depth / level``: the fraction of the pixel's light the shadow removes.
    level : (K, H, W) float64
        Lit level at the minimum (line through its window's ends).
    width : (K, H, W) float64
        Frames between the half-depth entry and exit crossings (NaN where open).
    time_std : (K, H, W) float64
        Noise standard deviation of `estimate`, frames.
    reason : (K, H, W) int8
        :data:`MINIMUM_REASONS`.
    count : (H, W) int64
        Significant minima found (neither missing nor low contrast; at most K).
    extra_contrast : (H, W) float64
        Contrast of the deepest further minimum (the (K+1)-th; 0 where none): a
        significant one means the pixel has more dips than K.
    depth_snr : (K, H, W) float64
        Depth of the smoothed minimum below its window's level over that depth's noise
        standard deviation (noise of the level and of the smoothed bottom, the bottom's
        scaled to its level by `noise_model`).
    noise : (H, W) float64
        Temporal noise of one raw sample at the lit level
        (:func:`shadowcam.lab.sensor_noise.pixel_noise`).
    lit_level : (H, W) float64
        Mean signal more than ``half_window`` frames from every minimum.
    n_frames : int
    significance : float
        `depth_snr` below which a minimum is ``low_contrast``: the depth pure noise reaches
        with probability ``false_alarm`` somewhere in the sweep.
    noise_model : (float, float)
        ``(gain, floor)`` of the sweep's Poisson-Gaussian noise (fitted or given).
    summary : DipSummary
        Each minimum's window (normalised by its lit level) and statistics, the timing
        methods' input: ``window`` (4 half_window + 1, K, H, W), the others (K, H, W).
    """

    time: np.ndarray
    estimate: np.ndarray
    frame: np.ndarray
    depth: np.ndarray
    contrast: np.ndarray
    level: np.ndarray
    width: np.ndarray
    time_std: np.ndarray
    reason: np.ndarray
    depth_snr: np.ndarray
    count: np.ndarray
    extra_contrast: np.ndarray
    noise: np.ndarray
    lit_level: np.ndarray
    n_frames: int
    significance: float
    noise_model: tuple = (float("nan"), float("nan"))
    summary: DipSummary = None


def select_minima(values, frames, count, *, separation):
    """The `count` deepest candidates that lie more than `separation` frames from each other.

    Parameters
    ----------
    values : (P, N) array_like
        Candidate smoothed minima (non-finite = empty slot).
    frames : (P, N) array_like of int
        Their frames.
    count : int
    separation : int
        Minimum distance, in frames, between selected minima (exclusive).

    Returns
    -------
    frame : (P, count) int64
        Selected frames, deepest first; -1 where fewer were found.
    value : (P, count) float64
        Their values (NaN where missing).

    Notes
    -----
    Greedy in (value, frame) order, like
    :func:`shadowcam.lab.dip_kernels.merge_dips` for ``count = 2``: equal values
    go to the earlier frame.
    """
    values = np.asarray(values, dtype=np.float64)
    frames = np.asarray(frames, dtype=np.int64)
    if values.shape != frames.shape or values.ndim != 2:
        raise ValueError(f"values and frames must be (P, N) arrays of one shape; got "
                         f"{values.shape} and {frames.shape}")
    if int(count) < 1:
        raise ValueError(f"count must be >= 1; got {count!r}")
    n_p = values.shape[0]
    finite = np.isfinite(values)
    order = np.lexsort((frames, np.where(finite, values, np.inf)), axis=-1)
    sorted_values = np.take_along_axis(values, order, -1)
    sorted_frames = np.take_along_axis(frames, order, -1)
    sorted_ok = np.take_along_axis(finite, order, -1)
    out_frame = np.full((n_p, int(count)), -1, np.int64)
    out_value = np.full((n_p, int(count)), np.nan)
    taken = np.zeros(n_p, np.int64)
    rows = np.arange(n_p)
    for n in range(values.shape[1]):
        f = sorted_frames[:, n]
        far = np.all((out_frame < 0) | (np.abs(out_frame - f[:, None]) > separation), axis=1)
        take = sorted_ok[:, n] & far & (taken < count)
        slot = np.minimum(taken, count - 1)
        out_frame[rows[take], slot[take]] = f[take]
        out_value[rows[take], slot[take]] = sorted_values[take, n]
        taken += take
    return out_frame, out_value


def _as_blocks(frames):
    """A callable giving the frame blocks again for each pass."""
    if callable(frames):
        return frames
    array = np.asarray(frames)
    if array.ndim not in (3, 4):
        raise ValueError(f"frames must be (T, H, W[, C]) or a callable giving such blocks; got "
                         f"shape {array.shape}")
    return lambda: (array[i:i + 64] for i in range(0, array.shape[0], 64))


def _lit_noise(passing):
    """Per-pixel noise standard deviation of a :class:`_WindowPass`'s lit frames (first differences)."""
    return np.sqrt(passing.diff_sq / np.maximum(passing.diff_count, 1) / 2.0)


def _site_windows(own, rest, normal, level, lit_level, replaced):
    """The own sites' :class:`~shadowcam.lab.site_signal.SiteWindow` of every minimum, in the
    units of its normalised window (its channel-sum line `level`, ``(K, W, P)``).

    `own`, `rest` are the :class:`_WindowPass` of the sites' own channel and of the rest of the
    channel sum; the samples that `normal` ((K, W, P) bool) excludes (another minimum's, or
    outside the dip) stay NaN, and those `replaced` by the lit level (another light's shadow)
    take the site's lit level. Its ``colour`` is left to the caller.
    """
    with np.errstate(invalid="ignore", divide="ignore"):
        centre = level[:, (level.shape[1] - 1) // 2, :]
        own_level = np.where(own.lit_count > 0, own.lit_sum / np.maximum(own.lit_count, 1), np.nan)
        rest_level = np.where(rest.lit_count > 0, rest.lit_sum / np.maximum(rest.lit_count, 1), np.nan)
        share = np.broadcast_to(own_level / lit_level, centre.shape)
        window = np.where(normal, own.window / level, np.nan)
        window = np.where(replaced, share[:, None, :], window).astype(np.float32)
        return SiteWindow(window=window.transpose(1, 0, 2), level=share, noise=_lit_noise(own)[None] / centre,
                          count=np.broadcast_to(own.lit_count, centre.shape),
                          neighbour_level=np.broadcast_to(rest_level / lit_level, centre.shape),
                          neighbour_noise=_lit_noise(rest)[None] / centre, colour=None)


class _WindowPass:
    """Second pass: raw windows around given frames, lit statistics more than `lit_gap`
    frames from all of them."""

    def __init__(self, centres, half_window, lit_gap):
        self.centres = centres  # (K, P) int64, -1 = none
        self.h = half_window
        self.lit_gap = lit_gap
        k, p = centres.shape
        self.window = np.full((k, 2 * half_window + 1, p), np.nan, np.float32)
        self.lit_sum = np.zeros(p)
        self.lit_count = np.zeros(p, np.int64)
        self.diff_sq = np.zeros(p)
        self.diff_count = np.zeros(p, np.int64)
        self.invalid = np.zeros((k, p), np.int64)
        self.previous = None
        self.next = 0

    def update(self, signal):
        """Feed the next frames, one at a time (memory ``O(K P)`` besides the windows)."""
        flat = signal.reshape(signal.shape[0], -1)
        present = self.centres >= 0
        columns = np.arange(flat.shape[1])
        for index, frame in enumerate(flat):
            t = self.next + index
            offset = t - (self.centres - self.h)  # (K, P)
            inside = present & (offset >= 0) & (offset <= 2 * self.h)
            finite = np.isfinite(frame)
            for k in range(self.centres.shape[0]):
                cols = columns[inside[k]]
                self.window[k, offset[k, cols], cols] = frame[cols]
            self.invalid += inside & ~finite
            outside = ~(present & (np.abs(t - self.centres) <= self.lit_gap)).any(axis=0) & finite
            self.lit_sum += np.where(outside, frame, 0.0)
            self.lit_count += outside
            if self.previous is not None:
                pair = outside & self.previous
                with np.errstate(invalid="ignore"):
                    self.diff_sq += np.where(pair, (frame.astype(np.float64) - self.previous_value) ** 2, 0.0)
                self.diff_count += pair
            self.previous, self.previous_value = outside, frame
        self.next += signal.shape[0]


def _side_means(window):
    """Mean value and mean slot of the first and of the last two valid samples of each
    window ``(K, W, P)``: ``(left, x_left), (right, x_right)``, each ``(K, P)``."""
    valid = np.isfinite(window)
    idx = np.arange(window.shape[1])[None, :, None]

    def side(from_left):
        rank = np.cumsum(valid if from_left else valid[:, ::-1], axis=1)
        rank = rank if from_left else rank[:, ::-1]
        pick = valid & (rank <= 2)
        count = pick.sum(axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            return (np.where(pick, window, 0).sum(axis=1) / count,
                    np.where(pick, idx, 0).sum(axis=1) / count)

    return side(True), side(False)


def _own_dip(window, detectable, inside):
    """Windows ``(K, W, P)`` with the samples of another light's shadow set to the lit level.

    Under a steady light the lit level is the same before and after a dip, and a shadow
    only removes light: a window end lower than the other end by more than `detectable`
    ((P,)) lies in another shadow (or, where the window was cut at another minimum, in
    this dip). On that side the dip ends at the sample nearest the centre that is back at
    the other end's level (within `detectable`); the slots beyond it that lie `inside` the
    sequence ((K, W, P) bool), cut or not, take that level (lit, as far as this dip goes).
    A side with no such sample, or whose ends agree, is left as it is.
    """
    (left, _), (right, _) = _side_means(window)
    n = window.shape[1]
    centre = (n - 1) // 2
    slots = np.arange(n)[None, :, None]
    out = window.copy()
    with np.errstate(invalid="ignore"):
        for low, high, side in ((left, right, slots < centre), (right, left, slots > centre)):
            shadowed = high - low > detectable[None]
            back = side & (window >= (high - detectable[None])[:, None])
            # the back-at-level sample nearest the centre on this side
            distance = np.where(back, np.abs(slots - centre), n)
            nearest = distance.min(axis=1)
            beyond = side & (np.abs(slots - centre) > nearest[:, None]) & (shadowed & (nearest < n))[:, None]
            out = np.where(beyond & inside, high[:, None], out)
    return out


def _line_level(window, trusted_left, trusted_right):
    """Lit level at each window slot, ``(K, W, P)``: the line through the means of the first
    and last two valid samples; a side whose window runs past the sequence (untrusted: its
    first valid samples may lie in the dip) counts only when its samples are within a tenth
    of the dip's depth of the other side's level, else takes the other side's level (NaN if neither)."""
    n = window.shape[1]
    valid = np.isfinite(window)
    idx = np.arange(n)[None, :, None]
    (left, x_left), (right, x_right) = _side_means(window)
    # an untrusted side still counts when its samples are within a tenth of the dip's depth
    # of the trusted side's level (the dip closes inside the sequence, before them)
    lowest = np.nanmin(np.where(valid, window, np.inf), axis=1)
    with np.errstate(invalid="ignore"):
        left_ok = trusted_left | (trusted_right & (left - lowest > 0.9 * (right - lowest)))
        right_ok = trusted_right | (trusted_left & (right - lowest > 0.9 * (left - lowest)))
    left, right = np.where(left_ok, left, np.nan), np.where(right_ok, right, np.nan)
    both = np.isfinite(left) & np.isfinite(right) & (x_right > x_left)
    with np.errstate(invalid="ignore", divide="ignore"):
        slope = np.where(both, (right - left) / (x_right - x_left), 0.0)
    anchor = np.where(np.isfinite(left), left, right)
    x0 = np.where(np.isfinite(left), x_left, x_right)
    return anchor[:, None] + slope[:, None] * (idx - x0[:, None])


def _merge_within_dips(window, centres, smoothed, slot_frame, outside_sequence, detectable):
    """Which minima are dips of their own, and which are deeper than `detectable` (P,).

    A minimum is part of a deeper one's dip (a flat or rippled bottom, two shadows that
    overlap) when the signal between them never comes back to the deeper dip's half
    depth; it is then dropped (``present`` False). Minima not deeper than `detectable`
    below their level (``dip`` False) cut no other minimum's window.
    """
    present = centres >= 0
    level = _line_level(window, ~outside_sequence[:, 0], ~outside_sequence[:, -1])
    with np.errstate(invalid="ignore"):
        dip = level[:, (window.shape[1] - 1) // 2] - smoothed > detectable[None]
    with np.errstate(invalid="ignore", divide="ignore"):
        uncut = window / level
    lowest = np.nanmin(np.where(np.isfinite(uncut), uncut, np.inf), axis=1)  # (K+1, P)
    half = 0.5 * (1.0 + lowest)
    depth_order = np.argsort(np.where(present, smoothed, np.inf), axis=0, kind="stable")
    w = (window.shape[1] - 1) // 2
    n = centres.shape[0]

    def of(values, index):
        return np.take_along_axis(values, index.reshape((1,) + (1,) * (values.ndim - 2) + (-1,)), 0)[0]

    for r_b in range(1, n):
        b = depth_order[r_b]
        f_b = of(centres, b)
        for r_a in range(r_b):
            a = depth_order[r_a]
            f_a = of(centres, a)
            frames_a = of(slot_frame, a)
            between = ((frames_a >= np.minimum(f_a, f_b)[None]) & (frames_a <= np.maximum(f_a, f_b)[None]))
            with np.errstate(invalid="ignore"):
                recovered = np.any(between & (of(uncut, a) >= of(half, a)[None]), axis=0)
            merged = of(present, a) & of(present, b) & (np.abs(f_b - f_a) <= w) & ~recovered
            columns = np.flatnonzero(merged)
            present[b[columns], columns] = False
    return present, dip


def _depth_snr(level, smoothed, noise, model, outside_sequence):
    """Depth of each smoothed minimum below its window's level over the depth's noise, (K, P).

    The depth is the level at the centre (the line through the means of two samples at each
    window end, or at one end where the window runs past the sequence) minus the [1, 2, 1] / 4
    smoothed minimum; their variances add. The pixel's variance `noise` ** 2 (at its lit
    level) scales to the dip's bottom by the Poisson-Gaussian `model` (shot noise follows
    the signal).
    """
    gain, floor = model
    with np.errstate(invalid="ignore", divide="ignore"):
        at_lit = gain * level + floor
        scale = np.where(np.isfinite(at_lit) & (at_lit > 0), (gain * np.maximum(smoothed, 0) + floor) / at_lit, 1.0)
        level_share = np.where(outside_sequence.any(axis=1), 0.5, 0.25)
        sigma = noise[None] * np.sqrt(_SMOOTHED_NOISE ** 2 * scale + level_share)
        return (level - smoothed) / sigma


#: pixels per row band of :func:`find_minima`'s per-pixel work (bounds its temporaries)
BAND_PIXELS = 2 ** 14


def _signal(block):
    block = np.asarray(block, dtype=np.float32)
    return block.sum(axis=-1) if block.ndim == 4 else block


@dataclass
class _Band:
    """One row band's two passes: each pixel's candidate minima, their raw windows and its lit
    statistics (the channel sum's; with RAW sites also the own sites' and the rest's)."""

    centres: np.ndarray  # (K + 1, P) int64, -1 = none
    smoothed: np.ndarray  # (K + 1, P)
    n_frames: int
    rows: int
    cols: int
    passing: _WindowPass = None
    own_pass: _WindowPass = None
    rest_pass: _WindowPass = None

    def lit_statistics(self):
        """Lit level, variance of one sample (first differences) and its degrees of freedom, each (P,)."""
        passing = self.passing
        with np.errstate(invalid="ignore", divide="ignore"):
            variance = passing.diff_sq / np.maximum(passing.diff_count, 1) / 2.0
            level = np.where(passing.lit_count > 0, passing.lit_sum / np.maximum(passing.lit_count, 1), np.nan)
        return level, variance, passing.diff_count


def row_bands(height, width, band_rows=None):
    """Consecutive row slices covering `height` rows of `width` pixels.

    Parameters
    ----------
    height, width : int
    band_rows : int, optional
        Rows per band (default: :data:`BAND_PIXELS` pixels' worth, at least one row).

    Returns
    -------
    list of slice
    """
    band_rows = max(1, BAND_PIXELS // max(int(width), 1)) if band_rows is None else int(band_rows)
    if band_rows < 1:
        raise ValueError(f"band_rows must be an integer >= 1; got {band_rows!r}")
    return [slice(r, min(r + band_rows, int(height))) for r in range(0, int(height), band_rows)]


def _track_bands(blocks, shape, bands, *, count, h, site_colour):
    """The two streaming passes over the frames, each block split into the row `bands`: one
    :class:`_Band` per band (memory per pixel, not per frame)."""
    cols = int(shape[1])
    trackers = [DipTracker((rows.stop - rows.start, cols), half_window=h) for rows in bands]
    for block in blocks():
        signal = _signal(block)
        for rows, tracker in zip(bands, trackers):
            tracker.update(signal[:, rows])
    out = []
    for rows, tracker in zip(bands, trackers):
        partial = tracker.partial()
        p = (rows.stop - rows.start) * cols
        chosen, smoothed = select_minima(partial.top_value.reshape(p, -1), partial.top_frame.reshape(p, -1),
                                         count + 1, separation=h)
        # the K deepest in order along the sweep (missing last), then the extra one
        order = np.argsort(np.where(chosen[:, :count] < 0, np.iinfo(np.int64).max, chosen[:, :count]), axis=1)
        order = np.concatenate([order, np.full((p, 1), count)], axis=1)
        centres = np.take_along_axis(chosen, order, 1).T  # (K + 1, P)
        # the second pass keeps twice the tracker's half window: a flat-bottomed dip's minimum
        # is its first lowest frame, and its whole width must still fit
        band = _Band(centres, np.take_along_axis(smoothed, order, 1).T, partial.end, rows.stop - rows.start, cols,
                     _WindowPass(centres, 2 * h, h))
        if site_colour is not None:
            band.own_pass, band.rest_pass = _WindowPass(centres, 2 * h, h), _WindowPass(centres, 2 * h, h)
        out.append(band)
    del trackers
    for block in blocks():
        signal = _signal(block)
        own = None if site_colour is None else own_site_samples(np.asarray(block, dtype=np.float32), site_colour)
        for rows, band in zip(bands, out):
            band.passing.update(signal[:, rows])
            if own is not None:
                band.own_pass.update(own[:, rows])
                band.rest_pass.update(signal[:, rows] - own[:, rows])
    return out


def _join_rows(parts):
    """Row bands' records (:class:`Minima`, and its nested summaries) joined into one: arrays
    along their row axis (the second to last), scalars from the first band."""
    first = parts[0]
    if len(parts) == 1:
        return first
    joined = {}
    for f in fields(first):
        values = [getattr(part, f.name) for part in parts]
        if isinstance(values[0], np.ndarray) and values[0].ndim >= 2:
            joined[f.name] = np.concatenate(values, axis=values[0].ndim - 2)
        elif is_dataclass(values[0]):
            joined[f.name] = _join_rows(values)
        else:
            joined[f.name] = values[0]
    return replace(first, **joined)


def find_minima(frames, shape, *, count, half_window=4, method="dip_centroid", false_alarm=1e-3,
                steady_level=True, noise_model=None, site_colour=None, band_rows=None):
    """The `count` deepest separated minima of each pixel, timed and classified.

    The frames are read twice (two passes), each block split into row bands whose per-pixel
    work (candidates, windows, timing) is done band by band; only the noise model is fitted
    over every pixel. The result does not depend on the bands, bit for bit.

    Parameters
    ----------
    frames : (T, H, W[, C]) array_like, or callable
        The sweep's frames, or a callable returning an iterable of consecutive
        ``(t, H, W[, C])`` blocks (called twice: two passes). Channels are summed.
    shape : (int, int)
        ``(H, W)``.
    count : int
        Minima wanted per pixel (lights, or wires of one family).
    half_window : int
        Minima closer than this many frames are one; each minimum is timed over the
        ``2 * half_window`` frames on each side of its smoothed minimum.
    method : str
        A key of :data:`shadowcam.lab.shadow_time_methods.SHADOW_TIME_METHODS` other than
        ``edge_fit`` (which mixes neighbours' times, possibly of other minima).
    false_alarm : float
        Probability that pure noise makes a minimum (sets ``significance``), and that a
        pixel following the noise model is taken for a noisier one.
    steady_level : bool
        The lit level is the same all along the sweep (a static light): a window whose
        ends stay more than a tenth of the dip's depth below the level of the frames far
        from every minimum has not reached the lit level (``wide_dip``, or
        ``overlapping`` when cut by another minimum). False under a moving light.
    noise_model : (gain, floor), optional
        The sensor's Poisson-Gaussian model (default: fitted to the sweep).
    site_colour : (H, W) int ndarray, optional
        Demosaiced RAW frames: the CFA channel of each site
        (:func:`shadowcam.lab.site_signal.cfa_site_colours`). The second pass also keeps
        each site's own samples, and each minimum's summary carries them as its ``site``
        (:class:`~shadowcam.lab.site_signal.SiteWindow`, in the units of its normalised
        window), from which ``edge_fit`` times it where its own dip is significant. Minima,
        their reasons and the other methods' times do not depend on it.
    band_rows : int, optional
        Rows per band (default: :data:`BAND_PIXELS` pixels' worth).

    Returns
    -------
    Minima
    """
    check_positive(count, "count")
    if int(count) != count:
        raise ValueError(f"count must be an integer >= 1; got {count!r}")
    check_in(method, "method", tuple(m for m in SHADOW_TIME_METHODS if m != "edge_fit"))
    if noise_model is not None:
        noise_model = tuple(float(v) for v in noise_model)
        if len(noise_model) != 2 or not all(np.isfinite(v) and v >= 0 for v in noise_model):
            raise ValueError(f"noise_model must be (gain, floor), two finite numbers >= 0; got {noise_model!r}")
    blocks = _as_blocks(frames)
    if site_colour is not None:
        site_colour = check_array(site_colour, "site_colour", shape=tuple(shape), dtype_kind="iu").astype(np.intp)
    count, h = int(count), int(half_window)
    bands = row_bands(shape[0], shape[1], band_rows)
    tracked = _track_bands(blocks, shape, bands, count=count, h=h, site_colour=site_colour)
    if noise_model is None:
        noise_model = fit_noise_model(*(np.concatenate(v) for v in zip(*(b.lit_statistics() for b in tracked))))
    parts = []
    for index, rows in enumerate(bands):
        parts.append(_finish_band(tracked[index], count=count, h=h, method=method, false_alarm=false_alarm,
                                  steady_level=steady_level, noise_model=noise_model,
                                  site_colour=None if site_colour is None else site_colour[rows]))
        tracked[index] = None  # the band's raw windows are no longer needed
    return _join_rows(parts)


def _finish_band(band, *, count, h, method, false_alarm, steady_level, noise_model, site_colour):
    """One band's minima from its passes (:class:`_Band`) under the sweep's `noise_model`: merged,
    cut, normalised, timed and classified, as a :class:`Minima` over the band's rows."""
    centres, smoothed, n_frames, passing = band.centres, band.smoothed, band.n_frames, band.passing
    own_pass, rest_pass, rows, cols = band.own_pass, band.rest_pass, band.rows, band.cols
    p, w = rows * cols, 2 * h
    window = passing.window
    slot_frame = centres[:, None, :] - w + np.arange(2 * w + 1)[None, :, None]  # (K+1, W, P)
    outside_sequence = (slot_frame < 0) | (slot_frame >= n_frames)
    far_level, own_variance, _ = band.lit_statistics()
    noise = pixel_noise(far_level, own_variance, passing.diff_count, model=noise_model,
                        false_alarm=false_alarm)
    significance = detection_threshold(n_frames, false_alarm=false_alarm)
    detectable = significance * _SMOOTHED_NOISE * noise
    present, dip = _merge_within_dips(window, centres, smoothed, slot_frame, outside_sequence, detectable)
    # each sample belongs to its nearest dip: cut the windows where they meet
    own = np.abs(slot_frame - centres[:, None, :])  # (K+1, W, P)
    nearest = np.ones(own.shape, bool)
    for other in range(centres.shape[0]):
        cuts = (present & dip)[other]
        nearest &= ~cuts[None, None] | (own <= np.abs(slot_frame - centres[other][None, None]))
    cut = np.where(nearest, window, np.nan)
    before_own_dip = cut
    if steady_level:
        cut = _own_dip(cut, detectable, ~outside_sequence)
    cut_by_other = ~nearest & np.isfinite(window)
    level = _line_level(cut, ~outside_sequence[:, 0], ~outside_sequence[:, -1]).astype(np.float64)
    with np.errstate(invalid="ignore", divide="ignore"):
        normalised = cut / level
    lit_level = far_level
    k_all = count + 1
    centre_level = level[:, w, :]
    lowest = np.nanmin(np.where(np.isfinite(normalised), normalised, np.inf), axis=1)
    contrast = np.where(present, 1.0 - lowest, np.nan)
    with np.errstate(invalid="ignore", divide="ignore"):  # absent minima: zero level, NaN depth
        relative_noise = noise[None] / centre_level
        raw_lowest = (1.0 - contrast) * centre_level
        depth = contrast * centre_level
    summary = DipSummary(
        window=normalised.transpose(1, 0, 2).astype(np.float32), window_start=centres - w,
        minimum_frame=centres, minimum_value=(1.0 - contrast).astype(np.float32),
        second_value=np.full((k_all, p), np.inf, np.float32), second_frame=np.full((k_all, p), -1),
        lit_level=np.ones((k_all, p)), noise=relative_noise,
        lit_count=np.broadcast_to(passing.lit_count, (k_all, p)), mean_level=np.ones((k_all, p)),
        invalid_count=passing.invalid, n_frames=n_frames)
    with np.errstate(invalid="ignore", divide="ignore"):
        estimate, entry, exit_, std = (np.asarray(a, np.float64) for a in SHADOW_TIME_METHODS[method](summary))
    if site_colour is not None:
        with np.errstate(invalid="ignore"):
            replaced = np.isfinite(cut) & (cut != before_own_dip)
            # the own site's dip lies within the channel sum's (the demosaic only widens it):
            # within its full width at half depth of its time
            extent = np.abs(slot_frame - estimate[:, None, :]) <= (exit_ - entry)[:, None, :]
        site = _site_windows(own_pass, rest_pass, nearest & extent, level, far_level, replaced & extent)
    depth_snr = _depth_snr(centre_level, smoothed, noise, noise_model, outside_sequence)
    with np.errstate(invalid="ignore"):
        strong = depth_snr > significance
    width = exit_ - entry
    reason = np.full((k_all, p), OK, np.int8)
    reason[~strong] = LOW_CONTRAST
    # under a steady level the window's ends must reach the level of the frames far from
    # every minimum (within a tenth of the dip's depth, and within what the noise of the
    # two means allows at `false_alarm`): else the dip is wider than the window, or runs
    # into the next one, and its crossings are not its own. Where that noise allowance
    # exceeds half the dip's depth the window's closure cannot be established: not timed.
    with np.errstate(invalid="ignore", divide="ignore"):
        end_level = np.minimum(level[:, 0, :], level[:, -1, :])
        end_noise = -ndtri(false_alarm) * noise * np.sqrt(0.5 + 1.0 / np.maximum(passing.lit_count, 1))
        unlit_ends = (~(end_level - raw_lowest >= 0.9 * (lit_level[None] - raw_lowest) - end_noise[None])
                      | (end_noise[None] > 0.5 * (lit_level[None] - raw_lowest)))
    open_dip = ~np.isfinite(width) | (unlit_ends if steady_level else False)
    # a cut window whose dip does not close: another minimum closer than their widths
    reason[strong & open_dip & cut_by_other.any(axis=1)] = OVERLAPPING
    reason[strong & open_dip & outside_sequence.any(axis=1)] = AT_END
    reason[(reason == OK) & open_dip] = WIDE
    reason[passing.invalid > 0] = INVALID
    reason[~present] = MISSING
    estimate = np.where(present, estimate, np.nan)
    time = np.where(reason == OK, estimate, np.nan)
    extra_contrast = np.where(present[count] & strong[count], contrast[count], 0.0)
    found = (present & strong)[:count].sum(axis=0)

    # order along the sweep again, minima merged into deeper ones last
    perm = np.argsort(np.where(present[:count], centres[:count], np.iinfo(np.int64).max), axis=0,
                      kind="stable")
    centres = np.where(present, centres, -1)

    def image(a):
        a = np.broadcast_to(np.asarray(a), (k_all, p))[:count]
        return np.take_along_axis(a, perm, 0).reshape(count, rows, cols)

    def slots(a):  # (W, K + 1, P) -> (W, K, H, W)
        return np.take_along_axis(a[:, :count], perm[None], 1).reshape(a.shape[0], count, rows, cols)

    def per_slot(record):
        return {f.name: (slots(getattr(record, f.name)) if f.name == "window" else image(getattr(record, f.name)))
                for f in fields(record) if isinstance(getattr(record, f.name), np.ndarray) and f.name != "colour"}

    per_minimum = replace(summary, **per_slot(summary))
    if site_colour is not None:
        per_minimum.site = replace(site, colour=site_colour.astype(np.int8), **per_slot(site))

    return Minima(time=image(time), estimate=image(estimate), frame=image(centres),
                  depth=image(depth), contrast=image(contrast), level=image(centre_level),
                  width=image(width), time_std=image(std), reason=image(reason),
                  depth_snr=image(depth_snr), count=found.reshape(rows, cols), extra_contrast=extra_contrast.reshape(rows, cols),
                  noise=noise.reshape(rows, cols), lit_level=lit_level.reshape(rows, cols),
                  n_frames=n_frames, significance=significance, noise_model=tuple(map(float, noise_model)),
                  summary=per_minimum)
