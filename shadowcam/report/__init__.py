"""Report figures and tables: matplotlib renderings of the products next to their ground truth.

Modules
-------
figures : report figures: matplotlib (Agg, no pyplot state) renderings of shadowcam products.
outdoor_figures : report figures of the outdoor pipeline: the equivalent of the paper's Fig. 18.
"""
