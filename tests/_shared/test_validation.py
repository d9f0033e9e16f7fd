"""The shared argument checks: one message form, ``<name> must be ...; got ...``."""

import numpy as np
import pytest

from shadowcam._shared.validation import (check_array, check_in, check_in_interval, check_positive,
                                          check_same_shape)


def test_checks_pass_values_through():
    array = check_array([[1, 2, 3]], "points", ndim=2, shape=(None, 3), dtype_kind="i")
    assert isinstance(array, np.ndarray) and array.shape == (1, 3)
    assert check_positive(2.5, "sigma") == 2.5
    assert check_in_interval(100, "percentile", 0, 100) == 100
    assert check_in("edge_fit", "method", {"edge_fit": None}) == "edge_fit"
    assert check_same_shape({"a": np.zeros((2, 3)), "b": np.ones((2, 3))}) == (2, 3)


@pytest.mark.parametrize("call, message", [
    (lambda: check_array(np.zeros(4), "image", ndim=(2, 3)), r"image must have 2 or 3 dimension\(s\); got shape \(4,\)"),
    (lambda: check_array(np.zeros((4, 2)), "points", shape=(None, 3)), r"points must have shape \(\*, 3\); got shape"),
    (lambda: check_array(np.zeros(4), "mosaic", dtype_kind="u"), "mosaic must have a dtype of kind 'u'; got float64"),
    (lambda: check_positive(float("nan"), "sigma"), "sigma must be > 0; got nan"),
    (lambda: check_positive(float("inf"), "scale", finite=True), "scale must be a finite number > 0; got inf"),
    (lambda: check_in_interval(0, "percentile", 0, 100), r"percentile must be in \(0, 100\]; got 0"),
    (lambda: check_in_interval(1, "false_alarm", 0, 1, closed="neither"), r"false_alarm must be in \(0, 1\); got 1"),
    (lambda: check_in("spline2", "method", ("spline", "cubic")), "method must be one of 'spline', 'cubic'; got 'spline2'"),
    (lambda: check_same_shape({"a": np.zeros(2), "b": np.zeros(3)}), r"a, b must have one shape; got a \(2,\), b \(3,\)"),
])
def test_failures_name_the_parameter_in_one_form(call, message):
    with pytest.raises(ValueError, match=message):
        call()
