"""CPU per fitted pixel of the penumbra law's fit, and its edges against another version's.

Fits dips drawn as the unit tests draw them (``tests/lab/test_penumbra_law.py``: disc and
box dips with an umbra, disc dips without, noise 0 and 0.01 of the lit level, footprint
spread up to 0.4 frame, whole-frame samples over 48 frames) with
:func:`shadowcam.lab.penumbra_law.fit_penumbra_law`, and prints the CPU (process time,
all threads) per fitted pixel after a warm-up call. With ``--reference FILE`` (a copy of
another version of ``penumbra_law.py``, e.g. ``git show main:shadowcam/lab/penumbra_law.py``)
the same dips are fitted by it too and the differences of first contact, last release and
the half-hidden crossings are printed (max and p99, frames), with the reference's CPU.

Usage: ``python scripts/benchmark_penumbra_fit.py [--pixels N] [--reference FILE]``
"""

import argparse
import importlib.util
import time

import numpy as np

from shadowcam.lab import penumbra_law


def test_dips(n, seed=0):
    """(times, samples, centre0, width0, spread, profile) of `n` dips per kind and profile."""
    rng = np.random.default_rng(seed)
    kinds = []
    for profile, umbra in (("disc", True), ("box", True), ("disc", False)):
        for noise in (0.0, 0.01):
            centre = rng.uniform(18, 30, n)
            extent = rng.uniform(1.5, 4, n) if umbra else rng.uniform(2, 5, n)
            width = (np.maximum(rng.uniform(4, 12, n), 2 * extent) if umbra
                     else 2 * rng.uniform(0.5, 1.0, n) * extent)
            full = rng.uniform(0, 0.3, n) if umbra else np.zeros(n)
            spread = rng.uniform(0, 0.4, n)
            times = np.tile(np.arange(48, dtype=np.float64), (n, 1))
            share = penumbra_law.hidden_share(times, centre[:, None], extent[:, None], width[:, None],
                                              spread=spread[:, None], profile=profile)
            samples = 1.0 - (1.0 - full[:, None]) * share + noise * rng.standard_normal(times.shape)
            kinds.append((f"{profile}{'' if umbra else ' no umbra'} noise {noise}",
                          (times, samples, centre.round(), width + 1.0, spread, profile),
                          (centre - 0.5 * width - extent, centre + 0.5 * width + extent)))
    return kinds


def fit_edges(module, dips, **options):
    """Edges of `module`'s fit of `dips`, and its process time (s)."""
    times, samples, centre, width, spread, profile = dips
    start = time.process_time()
    fit = module.fit_penumbra_law(times, samples, centre=centre, width=width, spread=spread, profile=profile,
                                  **options)
    used = time.process_time() - start
    return module.law_edges(fit), used


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--pixels", type=int, default=2000, help="dips per kind (6 kinds)")
    parser.add_argument("--reference", help="another version's penumbra_law.py to compare with")
    parser.add_argument("--starts", type=int, help="this version's grid points refined (default: its own)")
    args = parser.parse_args()
    modules = {"this": penumbra_law}
    if args.reference:
        spec = importlib.util.spec_from_file_location("reference_penumbra_law", args.reference)
        modules["reference"] = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(modules["reference"])
    options = {"this": {} if args.starts is None else {"starts": args.starts}, "reference": {}}
    kinds = test_dips(args.pixels)
    for key, module in modules.items():
        fit_edges(module, tuple(a[:8] if isinstance(a, np.ndarray) else a for a in kinds[0][1]),
                  **options[key])  # warm-up
    total = dict.fromkeys(modules, 0.0)
    for name, dips, (first, last) in kinds:
        edges = {}
        for key, module in modules.items():
            edges[key], used = fit_edges(module, dips, **options[key])
            total[key] += used
        error = np.abs(np.concatenate([edges["this"]["first"] - first, edges["this"]["last"] - last]))
        line = f"{name:24s} first/last error p95 {np.percentile(error, 95):.3f} max {error.max():.3f}"
        if args.reference:
            for edge in ("first", "last", "entry", "exit"):
                a, b = edges["this"][edge], edges["reference"][edge]
                both = np.isfinite(a) & np.isfinite(b)
                diff = np.abs(a - b)[both]
                line += (f"  {edge} max {diff.max(initial=0):.2e} p99 {np.percentile(diff, 99) if diff.size else 0:.2e}"
                         f" (NaN differs {int((np.isfinite(a) != np.isfinite(b)).sum())})")
        print(line)
    n = args.pixels * len(kinds)
    for key in modules:
        print(f"{key}: {total[key]:.2f} s CPU for {n} dips, {1e6 * total[key] / n:.1f} us per fitted pixel")


if __name__ == "__main__":
    main()
