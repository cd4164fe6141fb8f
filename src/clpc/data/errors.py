"""The error of unusable user data (shared by every module of :mod:`clpc.data`)."""

from __future__ import annotations

__all__ = ["DataError"]


class DataError(ValueError):
    """Raised when user data cannot be used as given (a :class:`ValueError`)."""
