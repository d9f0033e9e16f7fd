"""Argument checks with one error-message form: ``<name> must be ...; got ...``.

Every check raises :class:`ValueError` naming the parameter, and returns the
checked value (as an array for :func:`check_array`) so it can be used inline.

Offers
------
check_array : an array of a given number of dimensions, shape pattern and dtype kind.
check_positive : a number > 0 (optionally finite).
check_in_interval : a number inside an interval, each end open or closed.
check_in : one of a set of choices.
check_same_shape : arrays of one shape.
"""

import numpy as np


def _shape_text(shape):
    return "(" + ", ".join("*" if n is None else str(n) for n in shape) + ("," if len(shape) == 1 else "") + ")"


def check_array(value, name, *, ndim=None, dtype_kind=None, shape=None):
    """Return `value` as an array after checking its dimensions, shape and dtype kind.

    Parameters
    ----------
    value : array_like
    name : str
        Parameter name used in the message.
    ndim : int or tuple of int, optional, keyword-only
        Allowed numbers of dimensions.
    dtype_kind : str, optional, keyword-only
        Allowed :attr:`numpy.dtype.kind` characters, e.g. ``"u"`` or ``"biuf"``.
    shape : tuple of (int or None), optional, keyword-only
        Required shape; None matches any length on that axis (implies its ndim).

    Returns
    -------
    ndarray
    """
    array = np.asarray(value)
    if ndim is not None:
        allowed = (ndim,) if np.isscalar(ndim) else tuple(ndim)
        if array.ndim not in allowed:
            text = " or ".join(str(n) for n in allowed)
            raise ValueError(f"{name} must have {text} dimension(s); got shape {array.shape}")
    if shape is not None:
        if array.ndim != len(shape) or any(n is not None and n != m for n, m in zip(shape, array.shape)):
            raise ValueError(f"{name} must have shape {_shape_text(shape)}; got shape {array.shape}")
    if dtype_kind is not None and array.dtype.kind not in dtype_kind:
        raise ValueError(f"{name} must have a dtype of kind {dtype_kind!r}; got {array.dtype}")
    return array


def check_positive(value, name, *, finite=False):
    """Return `value` after checking that it is > 0 (and finite if `finite`); NaN fails."""
    if not value > 0 or (finite and not np.isfinite(value)):
        raise ValueError(f"{name} must be {'a finite number ' if finite else ''}> 0; got {value!r}")
    return value


def check_in_interval(value, name, low, high, *, closed="right"):
    """Return `value` after checking that it lies between `low` and `high`.

    Parameters
    ----------
    closed : {"right", "left", "both", "neither"}, keyword-only
        Which ends belong to the interval (default ``(low, high]``).
    """
    low_ok = value >= low if closed in ("left", "both") else value > low
    high_ok = value <= high if closed in ("right", "both") else value < high
    if not (low_ok and high_ok):
        left = "[" if closed in ("left", "both") else "("
        right = "]" if closed in ("right", "both") else ")"
        raise ValueError(f"{name} must be in {left}{low}, {high}{right}; got {value!r}")
    return value


def check_in(value, name, choices):
    """Return `value` after checking that it is one of `choices`."""
    if value not in choices:
        raise ValueError(f"{name} must be one of {', '.join(repr(c) for c in choices)}; got {value!r}")
    return value


def check_same_shape(arrays):
    """Check that the arrays of a ``{name: array}`` mapping share one shape; return their shape."""
    shapes = {name: np.shape(array) for name, array in arrays.items()}
    if len(set(shapes.values())) > 1:
        listed = ", ".join(f"{name} {shape}" for name, shape in shapes.items())
        raise ValueError(f"{', '.join(shapes)} must have one shape; got {listed}")
    return next(iter(shapes.values()))
