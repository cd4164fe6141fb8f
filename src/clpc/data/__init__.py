"""Measured records: :class:`IOData`, the one place user data are validated."""

from clpc.data.iodata import DataError, IOData, as_iodata

__all__ = ["DataError", "IOData", "as_iodata"]
