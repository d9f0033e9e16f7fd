"""Helpers shared by every wing of the library (no maths of their own).

Modules
-------
validation : argument checks with one error-message form, ``<name> must be ...; got ...``.
"""
