"""The light-field stage (paper VI, Fig. 17): a digital model of a real light source.

Modules
-------
hdr : HDR merge of bracketed RAW exposures into linear radiance (noise-optimal weights, reason codes).
screen : camera pixels to metric screen coordinates; the screen positions of a capture.
rays : ray correspondence between two screens through the mask coordinates; the rays dataset.
render : flux-conserving irradiance of the rays on any plane (position, tilt).
photometry_export : far-field candela table; IES LM-63-2002 and EULUMDAT files.
accuracy : rendered-screen and far-field errors against ground truth; the naive baseline.
"""
