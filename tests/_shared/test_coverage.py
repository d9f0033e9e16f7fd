import pytest

from shadowcam._shared.coverage import check_coverage


def test_a_covered_result_returns_its_fraction():
    assert check_coverage(50, 100, what="pixels") == 0.5
    assert check_coverage(1, 100, what="pixels", min_coverage=0.01) == 0.01


def test_an_empty_result_fails_with_the_reason_counts_largest_first():
    with pytest.raises(ValueError) as info:
        check_coverage(0, 36864, what="camera pixels timed in sweep u",
                       reasons={"never_shadowed": 64, "low_contrast": 36800, "saturated": 0},
                       hint="the sweep shows no shadow")
    message = str(info.value)
    assert message.startswith("0 of 36,864 camera pixels timed in sweep u (0.0%, min_coverage 0.01): "
                              "36,800 low_contrast, 64 never_shadowed; the sweep shows no shadow")
    assert "saturated" not in message and "min_coverage" in message


def test_nearly_empty_is_below_the_threshold_and_nothing_counts_as_empty():
    with pytest.raises(ValueError, match="9 of 1,000 pixels"):
        check_coverage(9, 1000, what="pixels", min_coverage=0.01)
    with pytest.raises(ValueError, match="0 of 0 pixels"):
        check_coverage(0, 0, what="pixels", min_coverage=0.0)
    with pytest.raises(ValueError, match="min_coverage must be"):
        check_coverage(5, 10, what="pixels", min_coverage=5)
