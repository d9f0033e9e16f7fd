"""The check that a stage's result is not empty or nearly empty.

A stage whose output covers (almost) no pixel must fail with the reason counts
instead of writing an empty product that later stages turn into an empty image.

Offers
------
MIN_COVERAGE : default smallest fraction of pixels a stage's result must cover.
check_coverage : return the covered fraction; raise ValueError with the reason counts below a threshold.
"""

from shadowcam._shared.validation import check_in_interval

#: default smallest covered fraction (1 %): real captures cover far more, an empty
#: or degenerate one (no shadow, too few frames, a threshold out of range) far less
MIN_COVERAGE = 0.01


def check_coverage(covered, total, *, what, reasons=None, hint="", min_coverage=MIN_COVERAGE):
    """Return ``covered / total``; raise ValueError if it is below `min_coverage`.

    Parameters
    ----------
    covered, total : int
        Pixels with a result and pixels in all.
    what : str
        What is counted, e.g. ``"camera pixels timed in sweep u"``.
    reasons : mapping of str to int, optional
        Why pixels have no result: reason -> pixel count (zero counts are left out).
    hint : str, optional
        What the counts mean for the capture, e.g. ``"the sweep shows no shadow"``.
    min_coverage : float, optional
        Smallest accepted fraction, in [0, 1].

    Returns
    -------
    float
        The covered fraction (0 when `total` is 0).

    Raises
    ------
    ValueError
        If `min_coverage` is outside [0, 1], or the fraction is below it (or `total`
        is 0): ``"0 of 36,864 camera pixels timed in sweep u (0.0%, min_coverage 0.01):
        36,864 low_contrast; the sweep shows no shadow"``.
    """
    min_coverage = float(check_in_interval(min_coverage, "min_coverage", 0.0, 1.0, closed="both"))
    covered, total = int(covered), int(total)
    fraction = covered / total if total else 0.0
    if total and fraction >= min_coverage:
        return fraction
    counts = sorted(((int(n), name) for name, n in (reasons or {}).items() if int(n)), reverse=True)
    detail = ", ".join(f"{n:,} {name}" for n, name in counts) or "no reason recorded"
    raise ValueError(
        f"{covered:,} of {total:,} {what} ({100 * fraction:.1f}%, min_coverage {min_coverage:g}): {detail}"
        + (f"; {hint}" if hint else "")
        + ". Check the capture, or lower min_coverage (config key min_coverage) to accept a nearly empty result"
    )
