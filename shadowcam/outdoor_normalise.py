"""First streaming pass over an outdoor time-lapse: registration, gains, levels.

Frames arrive one at a time in time order; the first is the reference. For
each frame: estimate its lit gain on pixels lit in the reference (shift-insensitive
median), mask the pixels the shadow reached, estimate the sub-pixel shift to
the reference (:mod:`shadowcam.registration`), resample, then estimate the lit
and sky gains again on the aligned frame (:mod:`shadowcam.photometric`) and
update the per-pixel shadow level (running minimum of the 3-frame smoothed
sky-normalised luminance). State is a few ``(H, W)`` arrays whatever the
number of frames.

Offers
------
SequenceNormaliser : the streaming pass; :meth:`update` per frame, :meth:`result`.
normalise_frames : run it over an iterable of frames.
aligned_luminance : one frame's registered luminance from the pass's results.
"""

import numpy as np

from shadowcam.photometric import estimate_gain, lit_at_start, luminance
from shadowcam.registration import apply_shift, shift_lucas_kanade_LucasKanade1981, static_weight
from shadowcam.sky_mask import auto_sky_mask

#: contrast (shadow / lit level) below which a pixel counts as having been shadowed
SHADOWED_CONTRAST = 0.3


class SequenceNormaliser:
    """Streaming registration and photometric normalisation.

    Parameters
    ----------
    sky : (H, W) bool ndarray, optional
        Sky mask (manifest override); default: :func:`shadowcam.sky_mask.auto_sky_mask`
        of the first frame.
    exposure_gain : (T,) ndarray, optional
        Gains from exposure metadata (NaN where unknown); seed the gain search.
    sky_params : dict, optional
        Options of :func:`shadowcam.sky_mask.auto_sky_mask`.
    """

    def __init__(self, *, sky=None, exposure_gain=None, sky_params=None):
        self._sky = None if sky is None else np.asarray(sky, dtype=bool)
        self._exposure = None if exposure_gain is None else np.asarray(exposure_gain, dtype=np.float64)
        self._sky_params = dict(sky_params or {})
        self.shifts, self.gain_lit, self.gain_sky, self.kept_lit = [], [], [], []
        self._recent = []

    def _start(self, frame):
        height, width = frame.shape[:2]
        if self._sky is None:
            self._sky = auto_sky_mask(frame, **self._sky_params)
        elif self._sky.shape != (height, width):
            raise ValueError(f"sky mask {self._sky.shape} does not match the frames ({height}, {width})")
        self.reference = frame.astype(np.float32)
        self.reference_luma = luminance(frame)
        self.lit_at_start, _ = lit_at_start(self.reference_luma, valid=~self._sky)
        self.shadowed_at_start = ~self._sky & ~self.lit_at_start
        self._shadow_min = np.full((height, width), np.inf, dtype=np.float32)

    def _prior(self, previous, k):
        if self._exposure is not None and k < self._exposure.size and np.isfinite(self._exposure[k]):
            return float(self._exposure[k]) * (previous / self._exposure[k - 1]
                                              if np.isfinite(self._exposure[k - 1]) else 1.0)
        return previous

    def update(self, frame):
        """Process the next frame ``(H, W, C)`` (the first call sets the reference)."""
        frame = np.asarray(frame, dtype=np.float32)
        if frame.ndim != 3:
            raise ValueError(f"frame must be (H, W, C); got shape {frame.shape}")
        k = len(self.shifts)
        if k == 0:
            self._start(frame)
            shift, gain_lit, gain_sky, kept, luma = np.zeros(2), 1.0, 1.0, int(self.lit_at_start.sum()), self.reference_luma
        else:
            if frame.shape != self.reference.shape:
                raise ValueError(f"frame {k} has shape {frame.shape}, the first frame {self.reference.shape}")
            raw = luminance(frame)
            rough, _ = estimate_gain(raw, self.reference_luma, pixels=self.lit_at_start,
                                     prior=self._prior(self.gain_lit[-1], k))
            weight = static_weight(raw, self.reference_luma, lit_reference=self.lit_at_start, gain=rough,
                                   valid=~self._sky)
            shift, _ = shift_lucas_kanade_LucasKanade1981(raw, self.reference_luma, weight=weight,
                                                          initial=self.shifts[-1])
            luma = apply_shift(raw, shift)
            gain_lit, kept = estimate_gain(luma, self.reference_luma, pixels=self.lit_at_start, prior=rough)
            gain_sky, _ = estimate_gain(luma, self.reference_luma, pixels=self.shadowed_at_start,
                                        prior=self.gain_sky[-1] * gain_lit / self.gain_lit[-1])
            if not self.shadowed_at_start.any():
                gain_sky = gain_lit
        self.shifts.append(np.asarray(shift, dtype=np.float64))
        self.gain_lit.append(float(gain_lit))
        self.gain_sky.append(float(gain_sky))
        self.kept_lit.append(int(kept))
        self._recent = (self._recent + [luma / np.float32(gain_sky)])[-3:]
        if len(self._recent) == 3:
            smooth = 0.25 * self._recent[0] + 0.5 * self._recent[1] + 0.25 * self._recent[2]
            np.minimum(self._shadow_min, smooth, out=self._shadow_min)

    def result(self):
        """Return the pass's results (a dict of arrays; see :func:`normalise_frames`)."""
        if not self.shifts:
            raise ValueError("no frames were given")
        if len(self.shifts) < 3:
            raise ValueError(f"an outdoor time-lapse needs at least 3 frames; got {len(self.shifts)}")
        ref = self.reference_luma
        with np.errstate(divide="ignore", invalid="ignore"):
            contrast = np.where(ref > 0, self._shadow_min / ref, np.inf)
        shadowed = self.lit_at_start & (contrast < SHADOWED_CONTRAST)
        ratio = float(np.median(contrast[shadowed])) if shadowed.any() else 0.1
        shadow_level = np.where(shadowed | self.shadowed_at_start, self._shadow_min, ratio * ref)
        lit_level = np.where(self.lit_at_start, ref, self._shadow_min / ratio)
        return {
            "shift": np.array(self.shifts),
            "gain_lit": np.array(self.gain_lit),
            "gain_sky": np.array(self.gain_sky),
            "kept_lit": np.array(self.kept_lit),
            "sky": self._sky,
            "lit_at_start": self.lit_at_start,
            "lit_level": lit_level.astype(np.float32),
            "shadow_level": shadow_level.astype(np.float32),
            "shadow_ratio": ratio,
            "reference": self.reference,
        }


def normalise_frames(frames, **options):
    """Run :class:`SequenceNormaliser` over `frames`.

    Parameters
    ----------
    frames : iterable of (H, W, C) ndarray
        In time order (e.g. flattened :func:`shadowcam.frame_store.iter_frame_chunks`).
    **options
        Keyword options of :class:`SequenceNormaliser`.

    Returns
    -------
    dict
        ``shift (T, 2)`` (row, col; pixels), ``gain_lit (T,)``, ``gain_sky (T,)``,
        ``kept_lit (T,)`` (pixels used for the lit gain), ``sky``,
        ``lit_at_start (H, W)`` bool, ``lit_level``, ``shadow_level (H, W)``
        (luminance of the reference frame's scale: lit in the reference, and
        sky-lit, normalised by ``gain_sky``), ``shadow_ratio`` (median
        shadow / lit level) and ``reference (H, W, C)``.
    """
    normaliser = SequenceNormaliser(**options)
    for frame in frames:
        normaliser.update(frame)
    return normaliser.result()


def aligned_luminance(frame, shift):
    """Registered luminance ``(H, W)`` float32 of `frame` ``(H, W, C)`` given its shift (row, col)."""
    return apply_shift(luminance(frame), shift)
