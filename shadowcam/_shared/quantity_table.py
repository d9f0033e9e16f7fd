"""Tables a reader scans: one row per quantity with value, unit, target and pass.

Accuracy reports are nested dictionaries of raw numbers (kept whole in their JSON);
their tables show each quantity once, rounded to :data:`DIGITS` significant digits,
with its unit and, where the quantity has a target, the target and whether it passes.

Offers
------
COLUMNS : the columns of a quantity table.
DIGITS : significant digits shown.
significant : a number as text with a few significant digits.
quantity_row : one row of a quantity table.
table_to_csv : a quantity table as CSV text.
"""

import csv
import io
import math

COLUMNS = ("quantity", "value", "unit", "target", "pass")
DIGITS = 3


def significant(value, digits=DIGITS):
    """`value` as text: integers whole, other numbers to `digits` significant digits.

    Booleans become ``yes``/``no``, None and NaN ``n/a``; text is returned as it is.
    """
    if value is None:
        return "n/a"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, str):
        return value
    if float(value).is_integer() and not isinstance(value, float):
        return str(int(value))
    value = float(value)
    if not math.isfinite(value):
        return "n/a"
    text = f"{value:.{digits}g}"
    if "e" in text and 1e-4 <= abs(value) < 10**digits:
        text = f"{value:f}".rstrip("0").rstrip(".")
    return text


def quantity_row(quantity, value, unit="", *, scale=1.0, target=None):
    """One row of a quantity table.

    Parameters
    ----------
    quantity : str
        What is measured, e.g. ``"shadow time |error| p95, sweep u"``.
    value : number, bool, str or None
        Raw value; numbers are multiplied by `scale` (e.g. 100 for a fraction in %).
    unit : str, optional
    scale : float, optional
    target : mapping, optional
        ``threshold``, ``comparison`` (``<=``, ``<``, ``>=``) and ``pass`` of the quantity's
        target; the threshold is scaled like the value.

    Returns
    -------
    dict
        Keys :data:`COLUMNS`, values text.
    """
    def scaled(number):
        is_number = isinstance(number, (int, float)) and not isinstance(number, bool)
        return number * scale if is_number and scale != 1.0 else number

    row = {"quantity": quantity, "value": significant(scaled(value)), "unit": unit, "target": "", "pass": ""}
    if target is not None:
        row["target"] = f"{target['comparison']} {significant(scaled(target['threshold']))}"
        row["pass"] = significant(bool(target["pass"]))
    return row


def table_to_csv(rows):
    """The rows of a quantity table as CSV text with the header :data:`COLUMNS`."""
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=COLUMNS, lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return buf.getvalue()
