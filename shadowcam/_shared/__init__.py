"""Small helpers shared by every wing of the package (no science here)."""
