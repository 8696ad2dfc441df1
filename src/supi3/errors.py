"""Named errors. Every error says which rule was broken, by which value, and where the rule comes from."""

from __future__ import annotations


class Supi3Error(Exception):
    """Base class of every error supi3 raises on purpose."""


class ConfigurationError(Supi3Error, ValueError):
    """A pin-strap combination the manual does not allow.

    Attributes
    ----------
    pins:
        The pins concerned, as the manual names them (``"C[4..0]"``, ``"MFP[15..12]"``, ...).
    value:
        The value given, as a bit string MSB first, or a short description.
    rule:
        The table or section that rules the combination out.
    """

    def __init__(self, pins: str, value: str, rule: str, detail: str) -> None:
        self.pins = pins
        self.value = value
        self.rule = rule
        self.detail = detail
        super().__init__(f"{pins} = {value}: {detail} ({rule})")


class ArgumentError(Supi3Error, TypeError, ValueError):
    """A public constructor or method was given an argument of the wrong type or out of its range.

    It is both a ``TypeError`` and a ``ValueError``, so code that caught either before still catches it. Raised
    through :mod:`supi3.checks`, whose messages read "X must be ..., not ...".

    Attributes
    ----------
    name:
        The argument, as the caller named it (``"position"``, ``"data"``, ``"pin 'mfp_in'"``).
    value:
        The value given.
    """

    def __init__(self, name: str, value: object, message: str) -> None:
        self.name = name
        self.value = value
        super().__init__(message)

    def __reduce__(self) -> tuple[type[ArgumentError], tuple[str, object, str]]:
        # Exception pickles as cls(*self.args), and args holds only the message.
        return type(self), (self.name, self.value, str(self))
