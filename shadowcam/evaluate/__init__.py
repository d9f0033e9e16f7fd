"""Evaluation tools above the product: simulation study, methods comparison, speed benchmark,
consistency of the renderers with their ground truth.

Modules
-------
methods_comparison : speed against error of every shadow-time and dual-view resampling method.
render_consistency : benchmark command: consistency of rendered outdoor captures with their ground truth.
simulation_study : the paper's simulation study (section II-C, Fig. 5), reproduced and extended.
speed_benchmark : speed benchmark of the shadow-time pipeline against its hardware floors (``make bench``).
"""
