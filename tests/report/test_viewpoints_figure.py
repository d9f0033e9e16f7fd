"""Tests of the viewpoints figure (paper Fig. 13 layout)."""

import numpy as np
import pytest

from shadowcam.report.figures import viewpoints_figure


def test_one_row_per_viewpoint_with_its_ground_truth_beside_it():
    rng = np.random.default_rng(0)
    rows = [(f"viewpoint {name}", rng.uniform(0, 1, (8, 9, 3)), rng.uniform(0, 1, (8, 9, 3)))
            for name in ("entry", "centre", "exit")]
    figure = viewpoints_figure(rows)
    titles = [axes.get_title() for axes in figure.axes]
    assert titles == [f"viewpoint {n}: {kind}" for n in ("entry", "centre", "exit")
                      for kind in ("dual view", "reciprocal render")]
    assert all(axes.get_xlabel().startswith("u (dual") and axes.get_ylabel().startswith("v (dual")
               for axes in figure.axes)
    assert len(viewpoints_figure([("viewpoint entry", rows[0][1], None)]).axes) == 1


def test_reciprocal_off_the_dual_grid_is_refused():
    with pytest.raises(ValueError, match="rows\\[0\\]"):
        viewpoints_figure([("entry", np.zeros((8, 9, 3)), np.zeros((9, 8, 3)))])
    with pytest.raises(ValueError, match="rows"):
        viewpoints_figure([])
