"""Files in and out: atomic writes, and typed, range-checked reading of TOML/JSON tables.

The foundation every other package may use; imports only ``rockyade.errors``.
"""
