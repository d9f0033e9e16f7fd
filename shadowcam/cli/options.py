"""Option parsing shared by the command-line steps.

Offers
------
parse_params : the ``--params`` JSON object, checked against the allowed keys.
"""

import json


def parse_params(text, *, allowed=None):
    """Parse a ``--params`` JSON string into a dict.

    Parameters
    ----------
    text : str
        JSON object text.
    allowed : iterable of str, optional
        Keys the step understands; any other key raises.

    Returns
    -------
    dict

    Raises
    ------
    ValueError
        When the text is not a JSON object or names an unknown key.
    """
    try:
        params = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ValueError(f"--params is not valid JSON: {exc}") from None
    if not isinstance(params, dict):
        raise ValueError(f"--params must be a JSON object, got {text!r}")
    if allowed is not None:
        unknown = set(params) - set(allowed)
        if unknown:
            raise ValueError(f"--params: unknown keys {sorted(unknown)}; allowed {sorted(allowed)}")
    return params
