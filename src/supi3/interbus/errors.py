"""Named errors of the INTERBUS wire layer, ring and master models."""

from __future__ import annotations

from supi3.errors import Supi3Error


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
