"""Small helpers shared by every wing of the library (no science here).

Modules
-------
atomic : atomic writes of files and directories (temporary name, renamed when complete).
validation : argument checks with one error-message form, ``<name> must be ...; got ...``.
"""
