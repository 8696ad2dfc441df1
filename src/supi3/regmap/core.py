"""The vocabulary of the register map: bit fields, byte layouts, registers, ports and the map itself.

Nothing in this module knows the SUPI 3 OPC; :mod:`supi3.regmap.registers` declares the chip with it.
"""

from __future__ import annotations

import numbers
import re
from dataclasses import dataclass, field
from enum import StrEnum
from functools import cached_property
from typing import Final

from supi3.errors import Supi3Error

BYTE_BITS: Final[int] = 8
"""Every register and every interface byte is 8 bits wide (3.4.4, 3.4.7)."""

BYTE_MASK: Final[int] = (1 << BYTE_BITS) - 1


class RegisterMapError(Supi3Error, ValueError):
    """A register-map declaration, look-up, value or export request that breaks a rule of the map."""


def integer(what: str, value: object) -> int:
    """``value`` as an ``int`` (Python and numpy integers; ``bool``, floats and strings are no register value)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise RegisterMapError(f"{what} must be an integer, not {value!r:.40} ({type(value).__name__})")
    return int(value)


def _byte(what: str, value: object) -> int:
    """``value`` as a register byte (0 to 255) of ``what`` (a field or layout name)."""
    byte = integer(what, value)
    if not 0 <= byte <= BYTE_MASK:
        raise RegisterMapError(f"{what}: {byte!r} is not a byte")
    return byte


def _member(what: str, value: object, kind: type[StrEnum]) -> None:
    """Refuse ``value`` unless it is one of ``kind``'s members (or its string value, which equals it)."""
    if not any(type(value) in (str, type(member)) and value == member for member in kind):
        raise RegisterMapError(f"{what} must be one of {', '.join(kind)}, not {value!r:.40}")


class AccessDirection(StrEnum):
    """Direction of the data access that follows a command byte, seen from the microprocessor (3.4.4)."""

    WRITE = "write"
    READ = "read"


class Access(StrEnum):
    """What one direction of one address does (Table 3-10, 3.4.7, 3.4.14); :attr:`meaning` says it in words.

    Register-backed accesses are ``R``, ``W`` and ``RC``; the others reach no register.
    """

    R = "r"
    W = "w"
    RC = "rc"
    RESERVED_IGNORED = "reserved-ignored"
    RESERVED_ZERO = "reserved-zero"
    NO_EFFECT = "no-effect"
    BLOCK_TRANSFER = "block-transfer"

    @property
    def meaning(self) -> str:
        """One sentence, with the manual section."""
        return _ACCESS_MEANING[self]


_ACCESS_MEANING: Final[dict[Access, str]] = {
    Access.R: "Read returns the register's value and leaves it unchanged.",
    Access.W: "Write stores the data byte.",
    Access.RC: "Read returns the value, then clears the event bits and releases /IRQ (3.4.14).",
    Access.RESERVED_IGNORED: "Reserved: the data access is ignored (written data rejected, read data "
    "invalid, the command byte is read back) and a command byte is expected next (3.4.4, 3.4.7).",
    Access.RESERVED_ZERO: "Reserved: a valid single-byte access that reaches no register and reads 00h.",
    Access.NO_EFFECT: "No write register: the data byte is accepted and discarded (3.4.7).",
    Access.BLOCK_TRANSFER: "The command byte itself starts a block transfer of all configured IN/OUT bytes, "
    "no data byte of its own follows (3.4.6).",
}

REGISTER_ACCESSES: Final[frozenset[Access]] = frozenset({Access.R, Access.W, Access.RC})
"""The accesses that reach a register; every other access reaches none."""


class Reset(StrEnum):
    """The events that can set registers back to their reset value (3.4.3, 3.4.7, Table 3-13)."""

    POWER_UP = "power-up"
    """Power-up (hardware) reset: clears every register (3.4.7)."""
    INTERBUS = "interbus"
    """INTERBUS reset, also the layer-2 watchdog reset of process data: clears the IN/OUT data only."""
    SAS_INIT = "sas-init"
    """SAS_INIT: re-initializes the serial interface; every register keeps its value (3.4.3)."""


_ASSUMPTION_ID: Final[re.Pattern[str]] = re.compile(r"[A-Z]+-[0-9]+")


@dataclass(frozen=True)
class Assumption:
    """A reference to a recorded project decision where the manual is silent or ambiguous.

    ``id`` is the entry's heading in ``docs/assumptions/*.md`` (``RM-7``, ``UP-21``); ``summary`` says in a few
    words what was decided, for generated outputs (the C header names both beside every macro that rests on it).
    """

    id: str
    summary: str

    def __post_init__(self) -> None:
        if not _ASSUMPTION_ID.fullmatch(self.id) or not self.summary:
            raise RegisterMapError(f"assumption id must look like 'RM-7' and have a summary, not {self.id!r}")


@dataclass(frozen=True)
class Enumerator:
    """A named value: of a field (unshifted) or of a whole byte (see :attr:`ByteLayout.constants`).

    ``assumptions``: the recorded decisions the value rests on beyond those of its field (a whole-byte constant
    has no field).
    """

    name: str
    value: int
    doc: str
    assumptions: tuple[Assumption, ...] = ()


@dataclass(frozen=True)
class Field:
    """A bit field of an 8-bit byte.

    Parameters
    ----------
    name:
        Identifier, upper case; unique within its layout.
    lsb:
        Position of the least significant bit, i.e. the shift of the field.
    width:
        Number of bits.
    doc:
        What the field means, with the manual section.
    access:
        ``None`` when the field behaves like its port's :class:`Access`; set to override it (the live I/O
        access bit inside the read-clear interrupt event register is ``Access.R``).
    overlays:
        Name of the field whose bits this one re-uses under another mode (CL2..0 over ID12..8 in the SET
        register); ``None`` for an ordinary field.
    values:
        Named field values, unshifted.
    assumptions:
        The recorded decisions (docs/assumptions) the field's position and width rest on; empty where the
        manual gives them.
    """

    name: str
    lsb: int
    width: int = 1
    doc: str = ""
    access: Access | None = None
    overlays: str | None = None
    values: tuple[Enumerator, ...] = ()
    assumptions: tuple[Assumption, ...] = ()

    def __post_init__(self) -> None:
        if self.width < 1 or self.lsb < 0 or self.lsb + self.width > BYTE_BITS:
            raise RegisterMapError(
                f"field {self.name}: bits [{self.lsb + self.width - 1}:{self.lsb}] do not fit in a byte"
            )
        for enumerator in self.values:
            if not 0 <= enumerator.value < 1 << self.width:
                raise RegisterMapError(
                    f"field {self.name}: value {enumerator.name} = {enumerator.value} needs more than {self.width} bits"
                )

    @cached_property
    def msb(self) -> int:
        """Position of the most significant bit."""
        return self.lsb + self.width - 1

    @cached_property
    def mask(self) -> int:
        """The field's bits in position."""
        return ((1 << self.width) - 1) << self.lsb

    def extract(self, byte: int) -> int:
        """Return the field's value (shifted down) from a register byte.

        Raises
        ------
        RegisterMapError
            If ``byte`` is not a byte (0 to 255).
        """
        return (_byte(self.name, byte) & self.mask) >> self.lsb

    def insert(self, byte: int, value: int) -> int:
        """Return ``byte`` with the field replaced by ``value``.

        Raises
        ------
        RegisterMapError
            If ``value`` does not fit in the field.
        """
        byte = _byte(self.name, byte)
        value = integer(f"field {self.name}", value)
        if not 0 <= value < 1 << self.width:
            raise RegisterMapError(f"field {self.name}: {value!r} does not fit in {self.width} bits")
        return (byte & ~self.mask & BYTE_MASK) | (value << self.lsb)

    def value(self, name: str) -> Enumerator:
        """Return the named value ``name`` of the field."""
        for enumerator in self.values:
            if enumerator.name == name:
                return enumerator
        raise RegisterMapError(f"field {self.name} has no value named {name!r}")


@dataclass(frozen=True, kw_only=True)
class ByteLayout:
    """The bit layout of one byte: a register, or an interface byte such as the command byte.

    ``constants`` names whole-byte values (the Intel initialization byte 81h, the block-transfer command CFh).
    """

    name: str
    title: str
    ref: str
    doc: str = ""
    fields: tuple[Field, ...] = ()
    constants: tuple[Enumerator, ...] = ()

    def __post_init__(self) -> None:
        names = [f.name for f in self.fields]
        if len(set(names)) != len(names):
            raise RegisterMapError(f"{self.name}: duplicate field names in {names}")
        taken = 0
        for f in self.base_fields:
            if taken & f.mask:
                raise RegisterMapError(f"{self.name}: field {f.name} overlaps another field")
            taken |= f.mask
        for f in self.fields:
            if f.overlays is not None and (self.field(f.overlays).mask & f.mask) != f.mask:
                raise RegisterMapError(f"{self.name}: field {f.name} is not inside {f.overlays}")

    @cached_property
    def base_fields(self) -> tuple[Field, ...]:
        """The fields that partition the byte (every field that overlays no other)."""
        return tuple(f for f in self.fields if f.overlays is None)

    @cached_property
    def mask(self) -> int:
        """The bits that carry a field; the others are reserved (write 0, read 0)."""
        result = 0
        for f in self.base_fields:
            result |= f.mask
        return result

    def field(self, name: str) -> Field:
        """Return the field called ``name``.

        Raises
        ------
        RegisterMapError
            If the layout has no such field.
        """
        for f in self.fields:
            if f.name == name:
                return f
        raise RegisterMapError(f"{self.name} has no field {name!r}; fields: {[f.name for f in self.fields]}")

    def constant(self, name: str) -> Enumerator:
        """Return the whole-byte constant called ``name``."""
        for c in self.constants:
            if c.name == name:
                return c
        raise RegisterMapError(f"{self.name} has no constant {name!r}")

    def encode(self, **values: int) -> int:
        """Build a byte from field values given by name, e.g. ``SET.encode(PCP_N=1, CL=0b010) == 0x82``."""
        byte = 0
        for name, value in values.items():
            byte = self.field(name).insert(byte, value)
        return byte

    def decode(self, byte: int) -> dict[str, int]:
        """Split a byte into the values of its base fields."""
        byte = _byte(self.name, byte)
        return {f.name: f.extract(byte) for f in self.base_fields}


@dataclass(frozen=True, kw_only=True)
class Register(ByteLayout):
    """An addressable register: a layout at an address, its reset value and the resets that restore it."""

    address: int
    cleared_by: frozenset[Reset]
    reset: int = 0


@dataclass(frozen=True)
class Port:
    """One direction of one address: what a data access there does (one cell of Table 3-10).

    ``register`` is the register reached; it is ``None`` exactly when ``access`` reaches no register. A write
    port and a read port holding the *same* :class:`Register` object share its storage (ID code, SET).
    """

    address: int
    direction: AccessDirection
    access: Access
    title: str
    register: Register | None = None

    def __post_init__(self) -> None:
        if (self.register is not None) != (self.access in REGISTER_ACCESSES):
            raise RegisterMapError(f"address {self.address} {self.direction}: {self.access} with {self.register}")
        if self.register is not None and self.register.address != self.address:
            raise RegisterMapError(f"{self.register.name} is at {self.register.address}, not {self.address}")
        allowed = (
            {Access.W, Access.NO_EFFECT}
            if self.direction is AccessDirection.WRITE
            else {Access.R, Access.RC, Access.RESERVED_ZERO}
        )
        if self.access not in allowed | {Access.RESERVED_IGNORED, Access.BLOCK_TRANSFER}:
            raise RegisterMapError(f"address {self.address}: {self.access} is not a {self.direction} access")

    @property
    def clear_on_read_mask(self) -> int:
        """The bits a read clears: those of the fields that follow an ``RC`` port; 0 for other ports."""
        if self.access is not Access.RC or self.register is None:
            return 0
        result = 0
        for f in self.register.base_fields:
            if f.access is None:
                result |= f.mask
        return result


@dataclass(frozen=True)
class RegisterMap:
    """The address area of the serial µP interface (3.4.7): two ports per address, plus the interface bytes.

    Look up with :meth:`port` (address and direction) or :meth:`register` (name).
    """

    address_bits: int
    ports: tuple[Port, ...]
    command_byte: ByteLayout
    init_byte: ByteLayout
    _by_key: dict[tuple[int, AccessDirection], Port] = field(init=False, repr=False, compare=False)
    _by_name: dict[str, Register] = field(init=False, repr=False, compare=False)
    """Every register once by name, in address order, the write register first where the two differ (the model's
    optical block looks its registers up every clock: computed once, the map is frozen)."""

    def __post_init__(self) -> None:
        by_key = {(p.address, p.direction): p for p in self.ports}
        expected = {(a, d) for a in range(1 << self.address_bits) for d in AccessDirection}
        if len(by_key) != len(self.ports) or set(by_key) != expected:
            raise RegisterMapError("every address needs exactly one write port and one read port")
        by_name: dict[str, Register] = {}
        for register in (p.register for p in self.ports if p.register is not None):
            if by_name.setdefault(register.name, register) != register:
                raise RegisterMapError(f"two registers called {register.name!r}")
        object.__setattr__(self, "_by_key", by_key)
        object.__setattr__(self, "_by_name", by_name)

    @property
    def addresses(self) -> range:
        """All relative addresses, 0 to 15."""
        return range(1 << self.address_bits)

    @property
    def registers(self) -> tuple[Register, ...]:
        """Every register once, in address order, the write register first where the two differ."""
        return tuple(self._by_name.values())

    def port(self, address: int, direction: AccessDirection) -> Port:
        """Return what a ``direction`` data access to ``address`` does.

        Raises
        ------
        RegisterMapError
            If ``direction`` is not one of :class:`AccessDirection`, or ``address`` is outside 0..15.
        """
        if type(direction) is not AccessDirection:  # the model's accesses: one test
            _member("direction", direction, AccessDirection)
        try:
            return self._by_key[(address, direction)]
        except KeyError:
            raise RegisterMapError(
                f"address {address!r} is outside the {1 << self.address_bits}-byte area (3.4.7)"
            ) from None

    def register(self, name: str) -> Register:
        """Return the register called ``name`` (e.g. ``"SET"``, ``"IRQ_EVT"``)."""
        try:
            return self._by_name[name]
        except (KeyError, TypeError):  # TypeError: an unhashable name
            raise RegisterMapError(f"no register {name!r}; registers: {list(self._by_name)}") from None

    def cleared_by(self, reset: Reset) -> tuple[Register, ...]:
        """The registers that ``reset`` sets back to their reset value (3.4.7).

        Raises
        ------
        RegisterMapError
            If ``reset`` is not one of :class:`Reset`.
        """
        if type(reset) is not Reset:
            _member("reset", reset, Reset)
        return tuple(r for r in self.registers if reset in r.cleared_by)
