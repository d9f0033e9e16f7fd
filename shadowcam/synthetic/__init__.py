"""Synthetic captures with exact ground truth: the lab and outdoor renderers and the sensor model.
Development and test tools: the product wings never import this package.

Modules
-------
lab : The lab renderer: scene description, ray casting, wire sweeps with exact ground truth.
outdoor : The outdoor renderer: terrain, sun, sunset frames with nuisances, exact ground truth.
sensor : sensor model: exposure, Poisson-Gaussian noise, black/white level, quantisation, Bayer mosaic.
"""
