"""Named errors of the INTERBUS wire layer, ring and master models."""

from __future__ import annotations

from collections.abc import Callable
from typing import ParamSpec, TypeVar

from supi3.errors import ArgumentError, Supi3Error

P = ParamSpec("P")
R = TypeVar("R")


class InterbusError(Supi3Error, ValueError):
    """A rule of the INTERBUS wire protocol or of the model's API was broken.

    Attributes
    ----------
    rule:
        The rule, as a section of ``docs/interbus.md`` or of the manual.
    value:
        The offending value, as given.
    detail:
        What is wrong with it.
    """

    def __init__(self, rule: str, value: object, detail: str) -> None:
        self.rule = rule
        self.value = value
        self.detail = detail
        super().__init__(f"{detail}: {value!r} ({rule})")


class TelegramError(InterbusError):
    """A line-level violation found while receiving telegrams (docs/interbus.md, "Telegrams").

    Attributes
    ----------
    bit:
        Index of the offending bit period in the level sequence being received.
    """

    def __init__(self, rule: str, value: object, detail: str, bit: int) -> None:
        self.bit = bit
        super().__init__(rule, value, f"{detail} at bit {bit}")


class InterbusArgumentError(ArgumentError, InterbusError):
    """An argument of the INTERBUS layer out of its type or range: an :class:`~supi3.errors.ArgumentError`
    ("X must be ..., not ...") that is also an :class:`InterbusError`, so code that caught either still does.

    Attributes
    ----------
    name, value:
        As :class:`~supi3.errors.ArgumentError`.
    rule, detail:
        As :class:`InterbusError` (``rule`` is the limit named in the message, ``detail`` the message).
    """

    def __init__(self, name: str, value: object, message: str, rule: str = "") -> None:
        self.name = name
        self.value = value
        self.rule = rule
        self.detail = message
        Exception.__init__(self, message)


def checked(check: Callable[P, R], *args: P.args, **kwargs: P.kwargs) -> R:
    """Run a :mod:`supi3.checks` check; its :class:`~supi3.errors.ArgumentError` becomes an
    :class:`InterbusArgumentError` (same message)."""
    try:
        return check(*args, **kwargs)
    except InterbusArgumentError:
        raise
    except ArgumentError as error:
        raise InterbusArgumentError(error.name, error.value, str(error), str(kwargs.get("limit", ""))) from None
