"""The µP-visible register file of the SUPI 3 OPC in the serial µP interface mode ("Init-µP").

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4.1, 3.4.3, 3.4.7 - 3.4.14, Tables 3-10 to 3-13. Access semantics, reset
values and reset classes come from :data:`supi3.regmap.REGISTER_MAP`; this module only gives them behaviour.

Two sides use a :class:`RegisterFile`:

* the serial µP interface (:mod:`supi3.spi.upif`) through :meth:`RegisterFile.cpu_read` and
  :meth:`RegisterFile.cpu_write`, one call per data byte;
* the INTERBUS slave core through the methods listed under "Core interface" in ``docs/upif.md``
  (:meth:`~RegisterFile.latch`, :meth:`~RegisterFile.event`, :meth:`~RegisterFile.bus_id_register`, ...).

Rule violations (reconfiguration during bus operation, inconsistent data access, and the interface's protocol
and timing rules) go to one :class:`ViolationLog` per chip: strict mode raises the named error, lenient mode
records it. In both modes the operation itself is carried out as the chip would.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from types import TracebackType
from typing import Final, Literal, TypeVar

from supi3 import tables
from supi3.checks import check_bits, check_bool, check_bytes, check_instance, check_int, describe
from supi3.config import DeviceConfig, MfpKind, Variant
from supi3.errors import ArgumentError, Supi3Error
from supi3.regmap import (
    INTERRUPT_SOURCES,
    REGISTER_MAP,
    Access,
    AccessDirection,
    RegisterMapError,
    Reset,
    SetConfig,
    decode_set,
)
from supi3.regmap.registers import IN_BYTES, IO_ACCESS_BIT, OUT_BYTES

__all__ = [
    "SUSPICIOUS_ACCESSES",
    "InconsistentDataError",
    "InterfaceViolationError",
    "ReconfigurationError",
    "RegisterArgumentError",
    "RegisterFile",
    "RegisterFileError",
    "SetRegisterError",
    "SuspiciousAccess",
    "SuspiciousAccessError",
    "ViolationLog",
    "event_mask",
]

_DATA_REGISTERS: Final[frozenset[str]] = frozenset(r.name for r in IN_BYTES + OUT_BYTES)
"""The INTERBUS data registers (3.4.8), the only ones the latch phase touches (3.4.14)."""
_OPTICAL_REGISTERS: Final[frozenset[str]] = frozenset({"LENGTH_OUT", "LENGTH_BRANCH", "POWER_IN", "POWER_OUT_BRANCH"})
_SOURCE_BITS: Final[dict[str, int]] = {s.name: s.bit for s in INTERRUPT_SOURCES}
_ALL_SOURCES: Final[int] = sum(1 << bit for bit in _SOURCE_BITS.values())
_PCP_ERASED: Final[tuple[str, ...]] = ("IN0", "IN1")
"""IN bytes erased after their transfer in a PCP device (/PCP = 0, 3.4.11)."""
_CONFIGURATION: Final[frozenset[str]] = frozenset({"SET", "ID"})
"""Written during initialization only (3.4.3, 3.4.10, 3.4.11)."""
_PCP_SOURCES: Final[int] = sum(1 << s.bit for s in INTERRUPT_SOURCES if s.name.startswith("PCP_"))
"""The IRQ_EN bits of the PCP interrupt sources (PCP receive, PCP send; Table 3-13)."""
_IN_INDEX: Final[dict[str, int]] = {r.name: r.address for r in IN_BYTES}
_OUT_INDEX: Final[dict[str, int]] = {r.name: r.address for r in OUT_BYTES}
_OUT_NAMES: Final[tuple[str, ...]] = tuple(r.name for r in OUT_BYTES)


def _port_names(direction: AccessDirection) -> tuple[str | None, ...]:
    ports = (REGISTER_MAP.port(a, direction) for a in REGISTER_MAP.addresses)
    return tuple(None if port.register is None else port.register.name for port in ports)


# The µP side runs once per data byte (millions of times for a firmware model): Table 3-10 flattened into
# per-address tuples, so that an access is a few index operations instead of port look-ups.
_READ_NAMES: Final[tuple[str | None, ...]] = _port_names(AccessDirection.READ)
"""The register a read of each address returns; ``None`` where it reaches none."""
_WRITE_NAMES: Final[tuple[str | None, ...]] = _port_names(AccessDirection.WRITE)
"""The register a write of each address stores; ``None`` where it reaches none."""
_READ_CLEARS: Final[tuple[int, ...]] = tuple(
    REGISTER_MAP.port(a, AccessDirection.READ).clear_on_read_mask for a in REGISTER_MAP.addresses
)
"""The bits a read of each address clears (read-clear ports, 3.4.14); 0 elsewhere."""
_WRITE_MASKS: Final[tuple[int, ...]] = tuple(
    0 if (register := REGISTER_MAP.port(a, AccessDirection.WRITE).register) is None else register.mask
    for a in REGISTER_MAP.addresses
)
"""The bits a write of each address stores; the others are reserved (write 0, read back 0)."""


def event_mask(*sources: str) -> int:
    """M33: the bits of IRQ_EVT (and IRQ_EN) of the interrupt ``sources`` (names of
    :data:`supi3.regmap.INTERRUPT_SOURCES`, Table 3-13), for :meth:`RegisterFile.raise_events`.

    Raises
    ------
    RegisterArgumentError
        If a source is not a source name.
    """
    mask = 0
    for source in sources:
        if type(source) is not str or source not in _SOURCE_BITS:
            raise RegisterArgumentError("source", source, f"source must be one of {sorted(_SOURCE_BITS)} (Table "
                                        f"3-13), not {describe(source)}: no interrupt source {source!r}")
        mask |= 1 << _SOURCE_BITS[source]
    return mask


class RegisterFileError(Supi3Error, ValueError):
    """A call that breaks the register file's API contract (a bad byte, an unknown source or register)."""


class RegisterArgumentError(ArgumentError, RegisterFileError):
    """An argument of a :class:`RegisterFile` method of the wrong type or out of its range ("X must be ..., not
    ..."): an :class:`~supi3.errors.ArgumentError` that code catching :class:`RegisterFileError` still catches."""


_T = TypeVar("_T")


def _checked(check: Callable[..., _T], *args: object, **kwargs: object) -> _T:
    """Run a :mod:`supi3.checks` check; its error comes out as a :class:`RegisterArgumentError`. The hot paths call
    this only after a cheap inline test failed, so a valid call never pays for it."""
    try:
        return check(*args, **kwargs)
    except ArgumentError as error:
        raise RegisterArgumentError(error.name, error.value, str(error)) from None


class InterfaceViolationError(Supi3Error):
    """A rule of the serial µP interface broken by the application or the master (strict mode raises it).

    Attributes
    ----------
    rule:
        Where the rule comes from: a manual section, table or timing parameter ("3.4.11", "Table 3-7 t1").
    detail:
        What happened.
    """

    def __init__(self, rule: str, detail: str) -> None:
        self.rule = rule
        self.detail = detail
        super().__init__(f"{detail} ({rule})")

    def __reduce__(self) -> tuple[object, ...]:
        return (type(self), (self.rule, self.detail))


class ReconfigurationError(InterfaceViolationError):
    """SET or ID written while the INTERBUS is running (3.4.3 note, 3.4.11: only during initialization)."""


class SetRegisterError(InterfaceViolationError):
    """SET written with a length code that Tables 3-11/3-12 reserve, or with ExtReg = 1 on the SUPI 3 LS (3.5,
    docs/assumptions/expansion.md RX-1); the configuration is not applied: the device is then unconfigured (UP-40)."""


class InconsistentDataError(InterfaceViolationError):
    """A data-register access overlapped the latch phase: the data may be inconsistent (3.4.14).

    Attributes
    ----------
    clock:
        The chip's 32 MHz clock count at the access (the clock source of :meth:`RegisterFile.use_clock`: the
        transaction-level chip's bus time, or the pin level's cycle), ``None`` if the register file has none.
    time_s:
        The same instant in seconds (``clock / 32 MHz``), ``None`` if unknown.
    """

    def __init__(self, rule: str, detail: str, clock: int | None = None) -> None:
        self.clock = clock
        self.time_s = None if clock is None else clock / tables.CLOCK_HZ
        self._what = detail
        when = "at an unknown time (no clock source)" if self.time_s is None else (
            f"at clock {clock} (t = {self.time_s:.9g} s)"
        )
        super().__init__(rule, f"{detail} {when}")

    def __reduce__(self) -> tuple[object, ...]:
        return (type(self), (self.rule, self._what, self.clock))


@dataclass(frozen=True)
class SuspiciousAccess:
    """One kind of legal but suspicious µP access that pedantic mode reports (docs/assumptions/upif.md, UP-30)."""

    decision: str
    """The decision in docs/assumptions/upif.md: ``"UP-31"``."""
    ref: str
    """Where the manual states the rule that makes the access suspicious: the error's ``rule``."""
    what: str
    """The kind in a few words: the start of the message."""


WRITE_TO_READ_ONLY: Final[SuspiciousAccess] = SuspiciousAccess(
    "UP-31", "3.4.7, Table 3-10", "write to a read-only address (no write register: no effect)"
)
WRITE_TO_RESERVED: Final[SuspiciousAccess] = SuspiciousAccess(
    "UP-32", "3.4.4, 3.4.7, Table 3-10", "write to a reserved address (the data byte is discarded)"
)
READ_OF_RESERVED: Final[SuspiciousAccess] = SuspiciousAccess(
    "UP-33", "3.4.4, 3.4.7, Table 3-10", "read of an address without a read register (the data byte is not a register)"
)
RESERVED_BITS: Final[SuspiciousAccess] = SuspiciousAccess(
    "UP-34", "3.4.11, 3.4.14, RM-4, RM-7", "write sets reserved bits (stored as 0)"
)
BEYOND_DATA_LENGTH: Final[SuspiciousAccess] = SuspiciousAccess(
    "UP-35", "3.4.8, 3.4.11", "data register outside the configured data length (not exchanged with INTERBUS)"
)
CONFIGURATION_REWRITTEN: Final[SuspiciousAccess] = SuspiciousAccess(
    "UP-36", "3.4.3, 3.4.10, 3.4.11", "configuration register written again after the configuration"
)
PCP_INTERRUPT_ON_IO_DEVICE: Final[SuspiciousAccess] = SuspiciousAccess(
    "UP-37", "3.4.11, Table 3-13", "PCP interrupt enabled on an I/O device (/PCP = 1: no PCP communication)"
)
OUT_BEFORE_DATA_CYCLE: Final[SuspiciousAccess] = SuspiciousAccess(
    "UP-38", "3.4.14, Table 3-13", "OUT data read before the first valid data cycle (reset value, not bus data)"
)
SUSPICIOUS_ACCESSES: Final[tuple[SuspiciousAccess, ...]] = (
    WRITE_TO_READ_ONLY, WRITE_TO_RESERVED, READ_OF_RESERVED, RESERVED_BITS, BEYOND_DATA_LENGTH,
    CONFIGURATION_REWRITTEN, PCP_INTERRUPT_ON_IO_DEVICE, OUT_BEFORE_DATA_CYCLE,
)  # fmt: skip
"""Every kind pedantic mode reports, one row each (UP-31 to UP-38)."""


class SuspiciousAccessError(InterfaceViolationError):
    """A legal but suspicious µP access, reported in pedantic mode only (``RegisterFile(..., pedantic=True)``).

    Attributes
    ----------
    kind:
        Which :data:`SUSPICIOUS_ACCESSES` row, with its decision ID (``kind.decision``, ``"UP-31"``).
    address, direction, value:
        The access: relative address, read or write, the data byte read or written.
    """

    def __init__(
        self, kind: SuspiciousAccess, address: int, direction: AccessDirection, value: int, detail: str
    ) -> None:
        self.kind = kind
        self.address = address
        self.direction = direction
        self.value = value
        self._what = detail
        super().__init__(kind.ref, f"pedantic {kind.decision}, {kind.what}: {detail}")

    def __reduce__(self) -> tuple[object, ...]:
        return (type(self), (self.kind, self.address, self.direction, self.value, self._what))


class ViolationLog:
    """The violations one chip has seen, in order; strict mode raises each one.

    Parameters
    ----------
    strict:
        ``True``: :meth:`report` raises the violation (after the operation that caused it completed, see
        :meth:`deferred`). ``False``: it is only recorded in :attr:`records`.
    """

    def __init__(self, strict: bool) -> None:
        self.strict = check_bool("strict", strict)
        self.records: list[InterfaceViolationError] = []
        self._depth = 0
        self._pending: list[InterfaceViolationError] = []
        self._deferred = _Deferred(self)

    def report(self, violation: InterfaceViolationError) -> None:
        """Record ``violation``; in strict mode raise it, or (inside :meth:`deferred`) at the end of the block."""
        if not isinstance(violation, InterfaceViolationError):
            _checked(check_instance, "violation", violation, InterfaceViolationError, "an InterfaceViolationError")
        self.records.append(violation)
        if not self.strict:
            return
        if self._depth:
            self._pending.append(violation)
        else:
            raise violation

    def deferred(self) -> _Deferred:
        """A context manager that holds strict-mode raises until the block ends, so that one operation (a byte, a
        clock cycle, a whole register access) completes and leaves the model consistent; then it raises the first
        violation reported inside it. Blocks nest: only the outermost one raises. An exception that leaves the
        block wins over the held violations (they stay in :attr:`records`)."""
        return self._deferred

    def hold(self) -> None:
        """Enter a :meth:`deferred` block by hand; :meth:`release` leaves it. For the per-byte hot paths, where a
        ``with`` statement costs more than the byte itself (bench/bench_upif.py)::

            log.hold()
            try:
                ...
            except BaseException:
                log.release(failed=True)
                raise
            log.release()
        """
        self._depth += 1

    def release(self, *, failed: bool = False) -> None:
        """Leave a block entered with :meth:`hold`: the outermost one raises the first violation held in it, unless
        the block ``failed`` (an exception left it; the violations stay in :attr:`records`).

        Raises
        ------
        RegisterFileError
            No block is held (a release without its :meth:`hold`); nothing changes.
        """
        if not self._depth:  # else strict mode would hold every later violation for ever
            raise RegisterFileError("ViolationLog.release() without a hold(): no deferred block is open")
        self._depth -= 1
        if self._depth == 0 and self._pending:
            pending, self._pending = self._pending, []
            if not failed:
                raise pending[0]


class _Deferred:
    """:meth:`ViolationLog.deferred` as a plain class (it runs once per clock cycle of the pin level)."""

    __slots__ = ("_log",)

    def __init__(self, log: ViolationLog) -> None:
        self._log = log

    def __enter__(self) -> None:
        self._log.hold()

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, trace: TracebackType | None
    ) -> Literal[False]:
        self._log.release(failed=kind is not None)
        return False


class RegisterFile:
    """The registers of Table 3-10 with their access semantics, resets and interrupt logic.

    Parameters
    ----------
    config:
        The pin-strap configuration; its MFP mode must be Init-µP. ``config.id_code`` is the µP_Not_Ready code the
        master sees until software writes SET (3.4.1, 3.4.3).
    strict:
        Raise violations (``True``) or only record them in :attr:`violations` (``False``).
    pedantic:
        Also report legal but suspicious µP accesses (:data:`SUSPICIOUS_ACCESSES`: a write to a read-only or
        reserved address, reserved bits set, a data register outside the data length, ...) as
        :class:`SuspiciousAccessError`, through :attr:`violations` like every other violation (UP-30). Off by
        default; off, it costs one flag test per access.

    Raises
    ------
    RegisterArgumentError
        If ``config`` is not a :class:`~supi3.config.DeviceConfig` of a µP interface mode, or ``strict`` or
        ``pedantic`` not a ``bool``.
    """

    def __init__(self, config: DeviceConfig, *, strict: bool = True, pedantic: bool = False) -> None:
        _checked(check_instance, "config", config, DeviceConfig, "a DeviceConfig (supi3.config.decode)")
        if config.mfp_mode.kind is not MfpKind.INIT_UP:
            raise RegisterArgumentError("config", config, f"config must be an Init-µP mode (Tables 2-4 to 2-7), not "
                                        f"{config.function!r}: that is not a serial µP interface mode")
        self.config = config
        self.violations = ViolationLog(_checked(check_bool, "strict", strict))
        self._pedantic = _checked(check_bool, "pedantic", pedantic)
        self._clock: Callable[[], int] | None = None
        self._values: dict[str, int] = {r.name: r.reset for r in REGISTER_MAP.registers}
        self._set: SetConfig | None = None
        self._internal = True  # derived from _set by _configure: the internal data registers are in the data path
        self._in_names: tuple[str, ...] = ()  # derived from _set by _configure: the IN registers of a data cycle
        self._erased: tuple[str, ...] = ()  # and those a PCP device erases after their transfer (3.4.11)
        self._length_code = 0  # and SET's length code (Table 3-12) as a number
        self._bus_running = False
        self._latch_phase = False
        self._io_access = False
        self._out_latched = False
        self._configured: set[str] = set()
        self.configurations = 0
        """How often a configuration was taken (SET applied, or dropped by a power-up reset): everything derived
        from SET (the data path, the data length, the ID register's length code) changes only when this moves, so
        a cache of it is keyed on this count (``Supi3``'s data path)."""
        self.power_up_reset()

    @property
    def pedantic(self) -> bool:
        """Suspicious accesses are reported (see the ``pedantic`` parameter; paused by :meth:`pedantic_paused`)."""
        return self._pedantic

    @contextmanager
    def pedantic_paused(self) -> Iterator[None]:
        """A block in which pedantic mode reports nothing: for bytes that a procedure of the manual sends, not the
        firmware (the no-op data byte completing a re-initialization, 3.4.3; UP-30)."""
        pedantic, self._pedantic = self._pedantic, False
        try:
            yield
        finally:
            self._pedantic = pedantic

    def use_clock(self, source: Callable[[], int] | None) -> None:
        """Tell the register file where the chip's time is: ``source()`` returns the 32 MHz clock count now (the
        transaction-level :class:`~supi3.model.chip.Supi3` installs its bus time; a pin-level model its cycle).
        Violations that name an instant (:class:`InconsistentDataError`) carry it; ``None``: time unknown."""
        if source is not None and not callable(source):
            raise RegisterArgumentError("source", source, "source must be a callable returning the clock count "
                                        f"or None, not {source!r}")
        self._clock = source

    @property
    def clock(self) -> int | None:
        """The chip's clock count now, from the source given to :meth:`use_clock`; ``None`` without one."""
        return None if self._clock is None else self._clock()

    # --------------------------------------------------------------------------------------------------------
    # Resets (3.4.3, 3.4.7)
    # --------------------------------------------------------------------------------------------------------

    def _reset(self, reset: Reset) -> None:
        for register in REGISTER_MAP.cleared_by(reset):
            self._values[register.name] = register.reset

    def power_up_reset(self) -> None:
        """Power-up (hardware) reset: every register 0, not configured, bus stopped, no latch phase (3.4.7)."""
        self._reset(Reset.POWER_UP)
        self._configure(None)
        self._bus_running = False
        self._latch_phase = False
        self._io_access = False
        self._out_latched = False
        self._configured.clear()

    def interbus_reset(self) -> None:
        """INTERBUS reset (or layer-2 watchdog reset): clear IN and OUT data, raise the INTERBUS reset event.

        Ref: 3.4.7, Table 3-13. Configuration (SET, ID) and every other register are kept.
        """
        self._reset(Reset.INTERBUS)
        self._out_latched = False
        self.event("IB_RESET")

    def sas_init(self) -> None:
        """SAS_INIT: the registers keep their values, SET and ID included (3.4.3)."""
        self._reset(Reset.SAS_INIT)

    # --------------------------------------------------------------------------------------------------------
    # µP side: one call per data byte (3.4.4, Table 3-10)
    # --------------------------------------------------------------------------------------------------------

    def cpu_read(self, address: int) -> int:
        """A µP read data access to ``address``: the byte the chip sends, with the access's side effects.

        Reading 14 returns the events plus the live I/O access bit D7, then clears the events it returned and
        releases /IRQ (3.4.14). Reading 6 returns 00h. A data register read during the latch phase reports
        :class:`InconsistentDataError`.

        Raises
        ------
        RegisterArgumentError
            If ``address`` is not 0..15, or for addresses 4, 5 and 15, whose accesses the interface handles itself
            (3.4.4, 3.4.6).
        """
        if type(address) is not int or not 0 <= address <= 15:
            address = self._address(address)
        name = _READ_NAMES[address]
        if name is None:
            return self._read_no_register(address)
        if self._latch_phase and name in _DATA_REGISTERS:
            self._inconsistent(name, "read")
        values = self._values
        value = values[name]
        cleared = _READ_CLEARS[address]
        if cleared:  # read-clear (RC): the events returned are cleared, the live I/O access bit D7 joins (3.4.14)
            values[name] = value & ~cleared
            value |= int(self._io_access) << IO_ACCESS_BIT
        if self._pedantic:
            self._suspicious_read(address, name, value)
        return value

    def _read_no_register(self, address: int) -> int:
        port = REGISTER_MAP.port(address, AccessDirection.READ)
        if port.access is not Access.RESERVED_ZERO:
            raise RegisterArgumentError("address", address, f"address must be a readable register, not {address}: "
                                        f"address {address} has no read register ({port.access.meaning})")
        if self._pedantic:
            self._suspicious(READ_OF_RESERVED, address, AccessDirection.READ, 0, "00h returned")
        return 0

    def cpu_write(self, address: int, value: int) -> None:
        """A µP write data access: store ``value`` (reserved bits read back 0), or nothing for 6 and 8-11.

        Writing SET applies the configuration (:meth:`bus_id_register`, :meth:`data_bits`); writing SET or ID
        while the bus runs reports :class:`ReconfigurationError` (3.4.3, 3.4.11); a SET value with a reserved
        length code reports :class:`SetRegisterError` and is stored but not applied: the device is then unconfigured,
        also after an earlier SET (UP-40).

        Raises
        ------
        RegisterArgumentError
            For an address outside 0..15, addresses 4, 5 and 15, or if ``value`` is not a byte.
        """
        if type(address) is not int or not 0 <= address <= 15:
            address = self._address(address)
        if type(value) is not int or not 0 <= value <= 0xFF:
            value = _checked(check_bits, "data byte", value, 8)
        name = _WRITE_NAMES[address]
        if name is None:
            self._write_no_register(address, value)
            return
        if self._latch_phase and name in _DATA_REGISTERS:
            self._inconsistent(name, "write")
        again = False
        if name in _CONFIGURATION:
            again = self._write_configuration(name, value & _WRITE_MASKS[address])
        else:
            self._values[name] = value & _WRITE_MASKS[address]
        if self._pedantic:
            self._suspicious_write(address, name, value, again)

    def _write_no_register(self, address: int, value: int) -> None:
        port = REGISTER_MAP.port(address, AccessDirection.WRITE)
        if port.access is not Access.NO_EFFECT:
            raise RegisterArgumentError("address", address, f"address must be a writable register, not {address}: "
                                        f"address {address} has no write register ({port.access.meaning})")
        if self._pedantic:
            reads = REGISTER_MAP.port(address, AccessDirection.READ).register is not None
            self._suspicious(WRITE_TO_READ_ONLY if reads else WRITE_TO_RESERVED, address, AccessDirection.WRITE, value,
                             "no effect")

    def _write_configuration(self, name: str, value: int) -> bool:
        """Write SET or ID; ``True`` if it was configured before and the bus is stopped (UP-36: during bus operation
        the write is a :class:`ReconfigurationError`)."""
        again = name in self._configured and not self._bus_running
        if self._bus_running:
            self.violations.report(
                ReconfigurationError("3.4.3, 3.4.11", f"{name} written with {value:02X}h during bus operation")
            )
        self._values[name] = value
        if name == "SET":
            self._apply_set(value)
        if name == "ID" or self._set is not None:  # a SET value that was not applied is no configuration
            self._configured.add(name)
        return again

    def _apply_set(self, value: int) -> None:
        """Configure the device with the SET value ``value``, or with none if it cannot apply (UP-20, UP-40: the
        configuration is always the stored SET's)."""
        try:
            decoded = decode_set(value)
        except RegisterMapError as error:
            self.violations.report(SetRegisterError("Table 3-12", f"{error}; configuration not applied"))
            self._configure(None)
            return
        if decoded.length.bits is None:
            self.violations.report(
                SetRegisterError("Table 3-11", f"SET {value:02X}h: length code {decoded.length.code} is reserved; "
                                 "configuration not applied")
            )
            self._configure(None)
            return
        if decoded.extreg and self.config.variant is Variant.LS:
            self.violations.report(
                SetRegisterError("3.5", f"SET {value:02X}h: ExtReg = 1 selects the serial register expansion, not "
                                 "possible with the SUPI 3 LS; configuration not applied")
            )
            self._configure(None)
            return
        self._configure(decoded)

    def _configure(self, decoded: SetConfig | None) -> None:
        """Take ``decoded`` as the configuration (``None``: none), with the tables a data cycle reads from it."""
        self._set = decoded
        self.configurations += 1
        self._internal = decoded is None or not decoded.extreg
        self._length_code = 0 if decoded is None else int(decoded.length.code, 2)
        self._in_names = tuple(r.name for r in IN_BYTES[: self.data_bytes()]) if self.internal_data_path else ()
        self._erased = tuple(name for name in _PCP_ERASED if name in self._in_names) if self.pcp_device else ()

    @staticmethod
    def _address(address: object) -> int:
        return _checked(check_int, "address", address, 0, 15, "A3..0, 3.4.7")

    def _inconsistent(self, register: str, what: str) -> None:
        self.violations.report(InconsistentDataError(
            "3.4.14", f"inconsistent data: {register} {what} during the latch phase", self.clock
        ))

    # --------------------------------------------------------------------------------------------------------
    # Pedantic mode: legal but suspicious accesses (UP-30 to UP-38), reported after the access took effect
    # --------------------------------------------------------------------------------------------------------

    def ignored_access(self, address: int, direction: AccessDirection, value: int) -> None:
        """The interface ignored a data access to reserved address 4 or 5 (3.4.4), which never reaches
        :meth:`cpu_read`/:meth:`cpu_write`: pedantic mode reports it, ``value`` being the byte read back (the
        command byte) or the byte discarded. Without pedantic mode nothing happens.

        Raises
        ------
        RegisterArgumentError
            If ``address`` is not an address whose ``direction`` access the chip ignores, or ``value`` not a byte.
        """
        direction = _checked(check_instance, "direction", direction, AccessDirection, "an AccessDirection")
        address = self._address(address)
        value = _checked(check_bits, "value", value, 8)
        if REGISTER_MAP.port(address, direction).access is not Access.RESERVED_IGNORED:
            raise RegisterArgumentError("address", address, f"address must be one whose {direction} access the chip "
                                        f"ignores (4, 5: 3.4.4), not {address}")
        if self._pedantic:
            kind = WRITE_TO_RESERVED if direction is AccessDirection.WRITE else READ_OF_RESERVED
            effect = "discarded" if direction is AccessDirection.WRITE else "the command byte sent back"
            self._suspicious(kind, address, direction, value, effect)

    def _suspicious(
        self, kind: SuspiciousAccess, address: int, direction: AccessDirection, value: int, detail: str
    ) -> None:
        write = direction is AccessDirection.WRITE
        register = REGISTER_MAP.port(address, direction).register
        other = REGISTER_MAP.port(address, AccessDirection.READ if write else AccessDirection.WRITE).register
        name = register.name if register is not None else "reserved" if other is None else (
            f"{'read' if write else 'write'}-only, {other.name}"
        )
        verb = "written to" if write else "read from"
        self.violations.report(SuspiciousAccessError(
            kind, address, direction, value, f"{value:02X}h {verb} address {address} ({name}): {detail}"
        ))

    def _suspicious_read(self, address: int, name: str, value: int) -> None:
        if name in _OUT_INDEX:
            if not self._in_data_length(_OUT_INDEX[name]):
                self._suspicious(BEYOND_DATA_LENGTH, address, AccessDirection.READ, value, self._data_length_text())
            elif not self._out_latched:
                self._suspicious(OUT_BEFORE_DATA_CYCLE, address, AccessDirection.READ, value,
                                 "no valid data cycle since power-up or INTERBUS reset")

    def _suspicious_write(self, address: int, name: str, value: int, again: bool) -> None:
        write = AccessDirection.WRITE
        reserved = value & ~_WRITE_MASKS[address]
        if reserved:
            self._suspicious(RESERVED_BITS, address, write, value, f"bits {reserved:02X}h are reserved, stored "
                             f"{value & _WRITE_MASKS[address]:02X}h")
        if name in _IN_INDEX:
            if not self._in_data_length(_IN_INDEX[name]):
                self._suspicious(BEYOND_DATA_LENGTH, address, write, value, self._data_length_text())
        elif again:
            self._suspicious(CONFIGURATION_REWRITTEN, address, write, value, "SET and ID are set once, during "
                             "initialization, and kept by SAS_INIT (3.4.3)")
        elif name == "IRQ_EN" and value & _PCP_SOURCES and self._set is not None and not self._set.extreg \
                and self._set.pcp_n:
            self._suspicious(PCP_INTERRUPT_ON_IO_DEVICE, address, write, value, f"PCP bits {value & _PCP_SOURCES:02X}h"
                             f" enabled, SET {self._values['SET']:02X}h configures an I/O device")

    def _in_data_length(self, index: int) -> bool:
        return self.internal_data_path and index < self.data_bytes()

    def _data_length_text(self) -> str:
        if not self.internal_data_path:
            return "ExtReg = 1: the internal data registers are not in the data path"
        if self._set is None:
            return "not configured: the data length is 0 until SET is written"
        return (f"the data length is {self.data_bits()} bits = {self.data_bytes()} byte(s) "
                f"(SET {self._values['SET']:02X}h)")

    # --------------------------------------------------------------------------------------------------------
    # Core interface: configuration seen by the master
    # --------------------------------------------------------------------------------------------------------

    @property
    def configured(self) -> bool:
        """Software has written a valid SET value since power-up (3.4.3)."""
        return self._set is not None

    def bus_id_register(self) -> int:
        """Bits 12..0 of the ID register the master reads in an ID cycle; the core adds bits 15..13.

        Bits 7..0 are the ID code, bits 12..8 the length code (ID12..ID8, Table 3-11). Before SET is written:
        the straps' µP_Not_Ready code with length code 00000 (3.4.1). After: the ID register (address 12) and
        the length code of SET, the abbreviated code decoded by Table 3-12 (3.4.11).
        """
        if self._set is None:
            return (self.config.length_code << 8) | self.config.id_code
        return (self._length_code << 8) | self._values["ID"]

    def data_bits(self) -> int:
        """Data length in bits per direction: 0 until SET is written (3.4.1), then SET's length (Table 3-11)."""
        if self._set is None:
            return 0
        bits = self._set.length.bits
        return 0 if bits is None else bits  # None never: _apply_set never applies a reserved length code

    def data_bytes(self) -> int:
        """The data length rounded up to whole bytes: how many of addresses 0.. take part in a data cycle."""
        return (self.data_bits() + 7) // 8

    @property
    def internal_data_path(self) -> bool:
        """``False`` with ExtReg = 1: the internal data registers are not in the data path (3.4.8, 3.4.11)."""
        return self._internal

    @property
    def pcp_device(self) -> bool:
        """/PCP = 0 without ExtReg: IN bytes 0 and 1 are erased after their transfer (3.4.11)."""
        return self._set is not None and not self._set.extreg and not self._set.pcp_n

    # --------------------------------------------------------------------------------------------------------
    # Core interface: data cycles, interrupts, management channel, optical registers
    # --------------------------------------------------------------------------------------------------------

    def set_bus_running(self, running: bool) -> None:
        """The core reports whether INTERBUS is in operation; SET/ID writes while it is are violations (3.4.3)."""
        if type(running) is not bool:
            running = _checked(check_bool, "running", running)
        self._bus_running = running

    @property
    def bus_running(self) -> bool:
        """What the core last reported with :meth:`set_bus_running`."""
        return self._bus_running

    def set_latch_phase(self, active: bool) -> None:
        """The core marks the latch phase of a data cycle; data-register accesses inside it are reported as
        inconsistent data (3.4.14)."""
        if type(active) is not bool:
            active = _checked(check_bool, "active", active)
        self._latch_phase = active

    @property
    def latch_phase(self) -> bool:
        """What the core last reported with :meth:`set_latch_phase`."""
        return self._latch_phase

    def set_io_access(self, busy: bool) -> None:
        """Set the I/O access (polling) bit: D7 of read 14 and the MFP1 level; 1 = no access now (Fig. 3-22)."""
        if type(busy) is not bool:
            busy = _checked(check_bool, "busy", busy)
        self._io_access = busy

    @property
    def io_access(self) -> bool:
        """The I/O access bit as last set by the core."""
        return self._io_access

    def _in_registers(self) -> tuple[str, ...]:
        if not self._internal:
            raise RegisterFileError("ExtReg = 1: the internal data registers are not in the data path (3.4.8)")
        return self._in_names

    def in_bytes(self) -> bytes:
        """The IN bytes the next data cycle sends, byte 0 (address 0) the most significant (3.4.8); no effect.

        ``data_bytes()`` bytes; for 2-bit and nibble lengths the data are the low bits of byte 0.

        Raises
        ------
        RegisterFileError
            With ExtReg = 1 (the data come from the external registers).
        """
        # the call only where it raises (ExtReg = 1); map: no Python call a byte (the data cycle's hot path)
        return bytes(map(self._values.__getitem__, self._in_names if self._internal else self._in_registers()))

    def latch(self, out: bytes) -> bytes:
        """The latch phase of a valid data cycle: return the IN bytes sent, store ``out`` in OUT0.., and in a
        PCP device erase the transferred ones of IN bytes 0 and 1 (3.4.11, 3.4.14).

        Parameters
        ----------
        out:
            The OUT data of the cycle, ``data_bytes()`` bytes, byte 0 the most significant.

        Raises
        ------
        RegisterArgumentError
            If ``out`` is not bytes of the configured length.
        RegisterFileError
            With ExtReg = 1.
        """
        names = self._in_names if self._internal else self._in_registers()  # the call only where it raises
        if type(out) is not bytes or len(out) != len(names):
            out = _checked(check_bytes, "out", out, len(names),
                           f"the OUT bytes of the cycle: latch needs {len(names)} OUT bytes for {self.data_bits()} "
                           "data bits, 3.4.8")
        values = self._values
        sent = bytes(map(values.__getitem__, names))
        values.update(zip(_OUT_NAMES, out, strict=False))
        self._out_latched = True
        for name in self._erased:
            values[name] = 0
        return sent

    def event(self, *sources: str) -> None:
        """An interrupt event of each of ``sources`` (names of :data:`supi3.regmap.INTERRUPT_SOURCES`, Table 3-13),
        at once (a valid data cycle's latch raises VALID, PCP_RX and PCP_TX together).

        An event bit is set only if its source is enabled in IRQ_EN; /IRQ is low while any event bit is set
        (3.4.14). Works whatever the data length, even 0.

        Raises
        ------
        RegisterArgumentError
            If a source is not a source name; no event bit is set then.
        """
        self.raise_events(event_mask(*sources))

    def raise_events(self, mask: int) -> None:
        """M33: :meth:`event` of the sources whose bits :func:`event_mask` gave as ``mask`` (checked once, where the
        mask was made: a chip's latch raises the same sources every cycle).

        Raises
        ------
        RegisterArgumentError
            If ``mask`` is not an integer of interrupt source bits only (Table 3-13); no event bit is set then.
        """
        if type(mask) is not int or mask & ~_ALL_SOURCES:  # a negative mask has bits beyond them too
            raise RegisterArgumentError("mask", mask, f"mask must be an integer of the interrupt source bits "
                                        f"{_ALL_SOURCES:02X}h (event_mask, Table 3-13), not {describe(mask)}")
        values = self._values
        values["IRQ_EVT"] |= values["IRQ_EN"] & mask

    @property
    def irq_n(self) -> int:
        """The /IRQ level (MFP3): 0 while an event is pending, else 1 (3.4.14)."""
        return 0 if self._values["IRQ_EVT"] else 1

    def processor_command(self, value: int) -> None:
        """The master's management message: store it in PCMD (read 7) and raise the PCMD event (3.4.9)."""
        value = _checked(check_bits, "processor command", value, 8, "3.4.9")
        self._values["PCMD"] = value
        self.event("PCMD")

    @property
    def processor_alarm(self) -> int:
        """The processor alarm register (write 7), for the master to read (3.4.9)."""
        return self._values["ALARM"]

    def set_optical(self, register: str, value: int) -> None:
        """Set one of the optical read registers 8-11 (3.4.12, 3.4.13) from the optical block.

        Raises
        ------
        RegisterArgumentError
            If ``register`` is not LENGTH_OUT, LENGTH_BRANCH, POWER_IN or POWER_OUT_BRANCH, or ``value`` sets a
            reserved bit.
        """
        if type(register) is not str or register not in _OPTICAL_REGISTERS:
            raise RegisterArgumentError("register", register, f"register must be one of {sorted(_OPTICAL_REGISTERS)}, "
                                        f"not {describe(register)}: {register!r} is not an optical register "
                                        "(3.4.12, 3.4.13)")
        layout = REGISTER_MAP.register(register)
        value = _checked(check_bits, "value", value, 8, "3.4.12, 3.4.13")
        if value & ~layout.mask:
            raise RegisterArgumentError("value", value, f"value must set only bits {layout.mask:02X}h of {register} "
                                        f"(3.4.12, 3.4.13), not {value:02X}h: bits outside {layout.mask:02X}h are "
                                        "reserved")
        self._values[register] = value

    def value(self, register: str) -> int:
        """The stored value of ``register`` (a :data:`REGISTER_MAP` name), without side effects (for tests and
        the core; IRQ_EVT without the live D7)."""
        if type(register) is not str or register not in self._values:
            raise RegisterArgumentError("register", register, f"register must be a name of REGISTER_MAP "
                                        f"({', '.join(sorted(self._values))}), not {describe(register)}: no register "
                                        f"{register!r}")
        return self._values[register]
