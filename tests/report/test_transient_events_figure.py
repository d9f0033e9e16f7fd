"""The transient-events figure counts the transient episodes of each pixel and shows when they began."""

import numpy as np
import pytest

from shadowcam.report.outdoor_figures import transient_events_figure


def test_counts_and_first_start_are_drawn_per_pixel():
    sky = np.zeros((6, 8), bool)
    sky[0] = True
    rows, cols = np.array([2, 2, 3, 4]), np.array([1, 1, 5, 6])
    start = np.array([600.0, 120.0, 300.0, 60.0])
    transient = np.array([True, True, True, False])
    figure = transient_events_figure(rows, cols, start, transient, sky=sky)
    count, first = (axes.images[0].get_array() for axes in figure.axes if axes.images)
    assert count[2, 1] == 2 and count[3, 5] == 1 and count[4, 6] == 0 and count.mask[0].all()
    assert first[2, 1] == pytest.approx(2.0) and first.mask[4, 6]
    with pytest.raises(ValueError, match="same"):
        transient_events_figure(rows, cols[:2], start, transient, sky=sky)


def test_arrival_event_table_selects_the_transient_episodes_by_their_flag():
    import xarray as xr

    from shadowcam.outdoor.arrival import EVENT_KINDS
    from shadowcam.report.outdoor_report import transient_events_of

    code = {name: c for c, name in EVENT_KINDS.items()}
    kinds = np.array([code["transient"], code["arrival"], code["transient"], code["shadowed_again"]], np.uint8)
    present = sorted(set(kinds.tolist()))
    arrival = xr.Dataset({
        "event_row": ("event", [2, 2, 3, 4]), "event_col": ("event", [1, 1, 5, 6]),
        "event_start_s": ("event", [600.0, 120.0, 300.0, 60.0]),
        "event_kind": ("event", kinds, {"flag_values": np.array(present, np.uint8),
                                        "flag_meanings": " ".join(EVENT_KINDS[c] for c in present)})})
    sky = np.zeros((6, 8), bool)
    figure = transient_events_of(arrival, sky=sky)
    count, first = (axes.images[0].get_array() for axes in figure.axes if axes.images)
    assert count[2, 1] == 1 and count[3, 5] == 1 and count[4, 6] == 0 and count.sum() == 2
    assert first[2, 1] == pytest.approx(10.0)
    assert transient_events_of(arrival.drop_vars("event_kind"), sky=sky) is None
