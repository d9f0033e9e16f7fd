"""Tests of shadowcam.evaluate.study_report: parameters checked, tables and figures of a study."""

import numpy as np
import pytest
import xarray as xr

from shadowcam.evaluate.study_report import TABLE_COLUMNS, format_table, study_from_params, write_study_figures


def _study():
    values = np.array([[96.0, 48.0, 12.0], [0.0, 2.0, np.nan]])
    metrics = {m: (("factor", "level"), np.arange(6, dtype=float).reshape(2, 3) / 10) for m in TABLE_COLUMNS}
    return xr.Dataset({"value": (("factor", "level"), values),
                       "factor_units": (("factor",), np.array(["frames", "mask steps"], dtype=object)),
                       **metrics},
                      coords={"factor": ["frames", "light_size"], "level": [0, 1, 2]})


def test_table_has_one_row_per_level_and_skips_missing_levels():
    lines = format_table(_study()).splitlines()
    assert lines[0] == "frames (frames)"
    assert lines[1].split() == ["value", *TABLE_COLUMNS.values()]
    assert [line.split()[0] for line in lines[2:5]] == ["96", "48", "12"]
    block = lines[lines.index("light_size (mask steps)"):]
    assert len([line for line in block if line and line[0] == " "]) == 3  # header + two levels, NaN skipped
    assert float(lines[3].split()[1]) == pytest.approx(0.1)


def test_figures_one_per_factor(tmp_path):
    write_study_figures(_study(), tmp_path / "figures")
    assert sorted(p.name for p in (tmp_path / "figures").iterdir()) == ["study_frames.png",
                                                                         "study_light_size.png"]


def test_unknown_parameters_are_refused_before_any_rendering():
    with pytest.raises(ValueError, match="baseline"):
        study_from_params({"baseline": {"no_such_factor": 1}})
    with pytest.raises(ValueError, match="unknown keys"):
        study_from_params({"sizes": 64})
