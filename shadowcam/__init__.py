"""shadowcam: shadow cameras recovered from moving shadows.

A library of pure functions on numpy arrays and xarray objects implementing
Koppal & Narasimhan, "Beyond Perspective Dual Photography with Illumination
Masks". File I/O lives in its own modules; the command line (``shadowcam``)
wraps the library and the Snakemake workflow calls the command line.
"""

__version__ = "0.1.0"
