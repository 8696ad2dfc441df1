"""An INTERBUS master at transaction level: reset, ID cycles, data cycles, configuration, diagnostics.

The master builds the summation frame, reads the ring's configuration in ID cycles, exchanges process data in
data cycles, checks loopback word, CRC and CNTR, latches a cycle only when all checks pass, locates errors, and
offers the services the manual names: Alarm Stop (1303h), Control_Device_Function / Quit Peripheral Error
(0714h), and the messages 0BB1h (peripheral fault) and 0C6Bh (watchdog). See docs/interbus.md, "Master".
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass
from enum import Enum
from itertools import takewhile
from typing import Final

from supi3.checks import check_bool, check_bytes, check_int, check_real, fail
from supi3.interbus import wire
from supi3.interbus.errors import InterbusError
from supi3.interbus.ring import BranchKind, Bus, ErrorKind, Transfer, lbd_position
from supi3.interbus.wire import BranchControl, Cycle
from supi3.tables import (
    ID_CODES,
    LENGTH_CODE_BY_VALUE,
    MODE_ROWS,
    UP_NOT_READY_ID_CODES,
    WATCHDOG_TIMEOUTS_S,
    IdCode,
)

# Firmware service and message codes named in the manual (3.4.14 Table 3-13, 3.6.2, Table 2-8).
ALARM_STOP: Final = 0x1303
CONTROL_DEVICE_FUNCTION: Final = 0x0714
MSG_PERIPHERAL_FAULT: Final = 0x0BB1
MSG_WATCHDOG: Final = 0x0C6B
MSG_MAU_WARNING: Final = 0x0BD4
"""OPT-52: the message a MAU warning coming on or going off raises (1.6.3 names none; the code is ours)."""

# A19 After a configuration error the master drops its table and, by default, rebuilds it from a discovery ID
# cycle in the next cycle() (docs/assumptions/interbus.md); Master(rediscover=False) waits for start() instead.
REDISCOVER: Final = True

# A20 How many diagnostics Master.diagnostics keeps (the oldest are dropped first; Master(max_diagnostics=...)).
DIAGNOSTICS_KEPT: Final = 1000

_LIMIT_DEVICES: Final = "manual: at most 512 devices in a ring"

BK_LBD_ID_CODE: Final = next(row.id_code for row in MODE_ROWS if row.function.startswith("BK-LBD"))
"""04h, the bus terminal module with a local bus branch with device-oriented diagnostics (Table 2-7)."""
STATUS_TERMINAL_ID_CODES: Final = frozenset(
    row.id_code for row in MODE_ROWS if row.table == "2-7" and "Init" not in row.function
)
"""The BKs without a µP (0Ch, 08h, 04h, Table 2-7): they answer a status request with their branch status (BK-5)."""
LBD_OR_ID_CODES: Final = frozenset(row.id_code for row in MODE_ROWS if row.function.startswith("LBD-OR"))
"""The ID codes of LBD-OR devices (Table 2-5): a BK-LBD branch of them has no return lines (BK-7)."""
COUNTED_KINDS: Final = frozenset({ErrorKind.DEAD_LINE})
"""The errors a BK-LBD's count can locate: an interrupt, the failing probe got no frame back (2.2.2: the diagnostic
telegram locates "a physical interrupt"). A frame that came back with errors (bit errors on a branch line) sent no
counter telegram, so the count (0: none, or the stale count of an earlier break) says nothing about it: the
segment search's position stands, the forward line into it (BK-62)."""


class InterfaceType(Enum):
    """Where a device sits, derived from its ID code's group in Table A-3."""

    REMOTE_BUS = "remote bus"
    LOCAL_BUS = "local bus"
    BUS_TERMINAL = "bus terminal"
    UNKNOWN = "unknown"
    """An ID code Table A-3 does not list; counted like a remote bus device (assumption A17)."""


_ID_ROWS: Final[dict[int, IdCode]] = {row.code: row for row in ID_CODES}


def interface_type(id_code: int) -> InterfaceType:
    """The interface type of an ID code: the group its Table A-3 row belongs to."""
    row = _ID_ROWS.get(id_code)
    if row is None:
        return InterfaceType.UNKNOWN
    if row.group.startswith("Bus terminal"):
        return InterfaceType.BUS_TERMINAL
    if row.group.startswith("Local bus"):
        return InterfaceType.LOCAL_BUS
    return InterfaceType.REMOTE_BUS


@dataclass(frozen=True)
class ConfigEntry:
    """One device of the configuration table read in an ID cycle.

    Attributes
    ----------
    ring_position:
        1..N, position 1 next to the master.
    segment, position:
        The device number ``segment.position``: a remote bus device or bus terminal opens a new segment at
        position 0, local bus devices follow at 1, 2, ... (assumption A17).
    id_code, length_code:
        ID register bits 7..0 and 12..8.
    data_bits, data_bytes:
        Data length of the length code (Table 3-11) and the bytes it occupies on the line (assumption A15).
    interface:
        Derived from the ID code (Table A-3).
    id_row:
        The Table A-3 row of the ID code, if listed.
    not_ready:
        The ID code is a µP_Not_Ready code (3.4.1): the device's processor has not configured it yet.
    """

    ring_position: int
    segment: int
    position: int
    id_code: int
    length_code: int
    data_bits: int
    data_bytes: int
    interface: InterfaceType
    id_row: IdCode | None
    not_ready: bool

    @property
    def number(self) -> str:
        """The device number as a G4 master prints it, ``"segment.position"``."""
        return f"{self.segment}.{self.position}"


@dataclass(frozen=True)
class Diagnostic:
    """One error or message reported by the master.

    Attributes
    ----------
    kind:
        What happened.
    location:
        Ring position *k* whose incoming line (or whose device) is at fault, N + 1 for the return line into
        the master; ``None`` if the master could not locate it.
    device:
        ``segment.position`` of the device at ``location``, if it is in the configuration.
    code:
        The firmware message code where the manual gives one (0BB1h, 0C6Bh).
    detail:
        Human-readable details.
    """

    kind: ErrorKind
    location: int | None
    device: str | None
    code: int | None
    detail: str
    return_line: bool = False
    """The fault is on the *return* line into ``location`` (an LBD branch's, found by the counter telegram)."""
    mau: tuple[str, bool] | None = None
    """A MAU warning's name (``"MAUWH"``, ``"MAUWR"``, ``"MAUWS"``) and whether it came on (OPT-52)."""


@dataclass(frozen=True)
class CycleResult:
    """Outcome of one cycle: its type, whether it was latched, and the diagnostics it produced."""

    cycle: Cycle
    ok: bool
    diagnostics: tuple[Diagnostic, ...]


_DATA_LATCHED: Final = CycleResult(Cycle.DATA, True, ())
"""Every latched data cycle's result (immutable, so one object serves them all)."""


class Master:
    """INTERBUS master model (docs/interbus.md, "Master").

    Parameters
    ----------
    ring:
        The ring the master drives.
    locate:
        After a failed cycle, locate the error with a diagnostic ID cycle and, if that fails too, a segment
        search (ID cycles with the ring closed after ring position *j*). Without it the master still finds a
        changed device count (manual 2.4: the data length change "triggers the diagnostic mechanisms"): an ID
        cycle whose loopback word comes back after fewer ID registers, or none, followed by a discovery-sized
        ID cycle (assumption A25).
    max_devices:
        Ring size the discovery ID cycle allows for (its filler is two bytes per device, assumption A14).
    rediscover:
        After a configuration error (a device count, ID code or length code that differs from the table), the
        table is dropped; ``True``: the next :meth:`cycle` rebuilds it with a discovery ID cycle; ``False``:
        :meth:`cycle` refuses to run until :meth:`start` (assumption A19).
    max_diagnostics:
        How many diagnostics :attr:`diagnostics` keeps; older ones are dropped and counted in
        :attr:`dropped_diagnostics` (assumption A20).

    Attributes
    ----------
    config:
        The configuration table read in the last discovery ID cycle, ``None`` before one.
    diagnostics:
        The last ``max_diagnostics`` diagnostics reported, oldest first (:meth:`clear_diagnostics` empties it).
    dropped_diagnostics:
        Diagnostics dropped from :attr:`diagnostics` to keep it bounded.
    stopped:
        ``True`` after a configuration error with ``rediscover=False``, until :meth:`start`.
    services:
        The last ``max_diagnostics`` firmware service codes called (``ALARM_STOP``,
        ``CONTROL_DEVICE_FUNCTION``), oldest first.
    """

    def __init__(
        self,
        ring: Bus,
        locate: bool = True,
        max_devices: int = wire.MAX_DEVICES,
        *,
        rediscover: bool = REDISCOVER,
        max_diagnostics: int = DIAGNOSTICS_KEPT,
    ) -> None:
        if not isinstance(ring, Bus):
            raise fail("ring", "a Ring or PinRing (the Bus protocol)", ring)
        self.ring = ring
        self.locate = check_bool("locate", locate)
        self.max_devices = check_int("max_devices", max_devices, 1, wire.MAX_DEVICES, _LIMIT_DEVICES)
        self.rediscover = check_bool("rediscover", rediscover)
        self.max_diagnostics = check_int("max_diagnostics", max_diagnostics, 0)
        self.config: tuple[ConfigEntry, ...] | None = None
        self.diagnostics: list[Diagnostic] = []
        self.dropped_diagnostics = 0
        self.stopped = False
        self._recover = False
        self.services: list[int] = []
        self._out = bytearray(wire.LOOPBACK_BYTES_ON_LINE)
        self._in = b""
        self._in_slices: list[slice] = []
        self._out_slices: list[slice] = []
        self._watchdog_code: int | None = None
        self._watchdog_pending = False
        self._quit: set[int] = set()
        self._attention = False
        self._pf_active: set[int] = set()
        self._pcmd: dict[int, int] = {}
        self._alarm_request: set[int] = set()
        self._alarm_expected: set[int] = set()
        self.processor_alarms: dict[int, int] = {}
        """Ring position -> the last processor alarm byte read from it (management channel, 3.4.9; emptied when the
        configuration is read anew, A19)."""
        self.branch_status: dict[int, wire.BkStatus] = {}
        """Ring position of a BK without µP -> its last branch status (BK-5), read after an ATTN no PF or WD bit
        explains and by the LBD location (emptied when the configuration is read anew)."""
        self._branch: dict[int, BranchControl] = {}
        self._alarm_output: dict[int, bool] = {}
        self._reconfigure = False
        self.mau_warnings: dict[int, tuple[bool, bool, bool]] = {}
        """Ring position -> its MAU warnings (MAUWH, MAUWR, MAUWS) as last read (OPT-52); a device without an entry
        has none on."""
        self._optical_request: set[int] = set()
        self._optical_expected: set[int] = set()
        self._explain: set[int] = set()

    # -- services ------------------------------------------------------------------------------------------------

    def alarm_stop(self) -> None:
        """Alarm Stop (1303h): INTERBUS reset of the whole ring, outputs and inputs reset, configuration
        forgotten; the next cycle is a discovery ID cycle. A watchdog setting is sent again afterwards."""
        self.services.append(ALARM_STOP)
        if len(self.services) > self.max_diagnostics:
            del self.services[: len(self.services) - self.max_diagnostics]
        self.ring.reset()
        self._set_config(None)
        self.stopped = False
        self._recover = False
        self._quit.clear()
        self._attention = False
        self._pf_active.clear()
        self._pcmd.clear()
        self._alarm_request.clear()
        self._alarm_expected.clear()
        self._branch.clear()
        self._alarm_output.clear()
        self._reconfigure = False
        self._forget_optical(False)
        self._watchdog_pending = self._watchdog_code is not None

    def start(self) -> CycleResult:
        """Alarm Stop, then a discovery ID cycle: the usual start-up."""
        self.alarm_stop()
        return self.id_cycle()

    def set_watchdog(self, timeout_s: float | None) -> None:
        """Set every device's layer-2 watchdog (Table 3-13: 0.05, 0.2, 1.0 s or ``None`` for off).

        Sent in the command words of the next ID cycle (assumption A9).
        """
        if timeout_s is not None:
            check_real("timeout_s", timeout_s, 0.0)
        if timeout_s not in WATCHDOG_TIMEOUTS_S:
            raise InterbusError("Table 3-13", timeout_s, f"watchdog time must be one of {WATCHDOG_TIMEOUTS_S}")
        self._watchdog_code = WATCHDOG_TIMEOUTS_S.index(timeout_s)
        self._watchdog_pending = True

    def quit_peripheral_error(self, position: int | str) -> None:
        """Control_Device_Function 0714h, "Quit Peripheral Error" (3.6.2): acknowledge a device's peripheral
        fault; the device's /ModAck output pulses. Sent in the device's command word of the next ID cycle."""
        self._quit.add(self.entry(position).ring_position)
        self.services.append(CONTROL_DEVICE_FUNCTION)
        if len(self.services) > self.max_diagnostics:
            del self.services[: len(self.services) - self.max_diagnostics]

    def processor_command(self, position: int | str, value: int) -> None:
        """Send a byte to a device's processor command register (management channel, 3.4.9): it arrives with
        the next ID cycle and raises the device's processor command interrupt (assumption A18)."""
        check_int("value", value, 0, 0xFF, "manual 3.4.9: a processor command is one byte")
        self._pcmd[self.entry(position).ring_position] = value

    def request_processor_alarm(self, position: int | str) -> None:
        """Read a device's processor alarm register (management channel, 3.4.9): the request goes out with the
        next ID cycle and the value comes back in the one after, into :attr:`processor_alarms` (A18)."""
        self._alarm_request.add(self.entry(position).ring_position)

    def switch_branch(self, position: int | str, on: bool, extended: bool = False) -> None:
        """Switch a bus terminal module's branch off or on (2.4), on with the extended BK function if ``extended``
        (the BK then closes its branch itself when its return line stays silent, BK-3).

        Sent in the BK's command word of the next ID cycle (BK-4); once latched, the master reads the configuration
        anew (a discovery ID cycle, no configuration error) and the OUT data start from zeros.

        Raises
        ------
        InterbusArgumentError
            ``on`` or ``extended`` is not a bool.
        InterbusError
            No such device, or it is no bus terminal module (Table 2-7), or ``extended`` with ``on`` False.
        """
        on = check_bool("on", on)
        extended = check_bool("extended", extended)
        entry = self.entry(position)
        if entry.interface is not InterfaceType.BUS_TERMINAL:
            raise InterbusError("Table 2-7", position, f"device {entry.number} must be a bus terminal module to "
                                f"switch a branch, not ID code {entry.id_code:02X}h")  # fmt: skip
        if extended and not on:
            raise InterbusError("2.4", extended, "the extended BK function is activated with the branch on")
        control = BranchControl.OFF if not on else BranchControl.ON_EXTENDED if extended else BranchControl.ON
        self._branch[entry.ring_position] = control

    def set_alarm_output(self, position: int | str, on: bool) -> None:
        """Set a bus terminal module's ALARM output (MFP15, Table 2-8: set by the master with 0714h) on or off; sent
        in its command word of the next ID cycle (BK-12). An Alarm Stop switches it off.

        Raises
        ------
        InterbusArgumentError
            ``on`` is not a bool.
        InterbusError
            No such device, or it is no bus terminal module (Table 2-7).
        """
        on = check_bool("on", on)
        entry = self.entry(position)
        if entry.interface is not InterfaceType.BUS_TERMINAL:
            raise InterbusError("Table 2-8", position, f"device {entry.number} must be a bus terminal module to "
                                f"set its ALARM output, not ID code {entry.id_code:02X}h")  # fmt: skip
        self._alarm_output[entry.ring_position] = on

    # -- process data --------------------------------------------------------------------------------------------

    def entry(self, position: int | str) -> ConfigEntry:
        """The configuration entry of a ring position (int, 1..N) or a device number (``"segment.position"``)."""
        if not isinstance(position, str):
            check_int("position", position, 1, wire.MAX_DEVICES, _LIMIT_DEVICES)
        config = self._require_config()
        if not isinstance(position, str):
            if 1 <= position <= len(config):
                return config[position - 1]
        else:
            for entry in config:
                if entry.number == position:
                    return entry
        raise InterbusError("docs/interbus.md, Master", position, "no such device in the configuration")

    def set_outputs(self, position: int | str, data: bytes) -> None:
        """Set the OUT data sent to a device from the next data cycle on."""
        entry = self.entry(position)
        check_bytes("data", data)
        if len(data) != entry.data_bytes:
            raise InterbusError("Table 3-11", data, f"device {entry.number} takes {entry.data_bytes} bytes")
        self._out[self._out_slices[entry.ring_position - 1]] = data

    def outputs(self, position: int | str) -> bytes:
        """The OUT data currently set for a device."""
        return bytes(self._out[self._out_slices[self.entry(position).ring_position - 1]])

    def inputs(self, position: int | str) -> bytes:
        """The IN data of a device from the last valid data cycle (zeros before one)."""
        return self._in[self._in_slices[self.entry(position).ring_position - 1]]

    # -- cycles --------------------------------------------------------------------------------------------------

    def cycle(self) -> CycleResult:
        """Run the next cycle a master would: an ID cycle when there is no configuration, a command to send
        or a device asking for attention, and after a failed cycle until an ID cycle is latched (so that no TE
        bit outlives the error it belongs to, assumption A21); else a data cycle."""
        if self.stopped:
            self._require_running()  # raises
        pending = self._pcmd or self._alarm_request or self._alarm_expected or self._recover or self._branch \
            or self._optical_request or self._optical_expected or self._alarm_output
        if self.config is None or self._attention or self._watchdog_pending or self._quit or pending:
            return self.id_cycle()
        return self.data_cycle()

    def data_cycle(self) -> CycleResult:
        """One data cycle: send the OUT data, receive the IN data, latch if every check passes."""
        if self.config is None:
            self._require_config()  # raises
        data_len = len(self._out) - wire.LOOPBACK_BYTES
        transfer = self.ring.transfer(Cycle.DATA, bytes(self._out))
        problem = self._check(transfer, data_len)
        self.ring.finish(transfer, problem is None)
        if problem is not None:
            return self._failed(Cycle.DATA, problem)
        assert transfer.returned is not None
        self._in = transfer.returned[:data_len]
        self._attention = self._attention or transfer.flags.attention
        return _DATA_LATCHED

    def id_cycle(self) -> CycleResult:
        """One ID cycle: a discovery cycle without a configuration (the loopback word is searched for), else
        a cycle over the known ring that also carries the command words; stopped (``rediscover=False``, A19) it waits
        for :meth:`start` as :meth:`cycle` does."""
        if self.config is None:
            self._require_running()
            return self._discovery()
        config = self.config
        optical = self._optical_request - self._alarm_request - self._pcmd.keys()  # one answer each (OPT-50)
        words = [self._command(entry.ring_position, entry.ring_position in optical) for entry in reversed(config)]
        data = wire.LOOPBACK_BYTES_ON_LINE + b"".join(wire.word_bytes(w) for w in words)
        transfer = self.ring.transfer(Cycle.ID, data)
        problem = self._check(transfer, 2 * len(config))
        registers: list[int] = []
        if problem is None:
            assert transfer.returned is not None
            registers = _id_registers(transfer.returned, len(config))
            problem = _compare(config, registers, self._answering)
        elif problem.kind is ErrorKind.LOOPBACK and transfer.returned is not None:
            problem = _fewer(config, transfer.returned, self._answering) or problem
        self.ring.finish(transfer, problem is None)
        if problem is not None:
            return self._failed(Cycle.ID, problem)
        self._recover = False
        self._watchdog_pending = False
        self._quit.clear()
        for ring_position in self._alarm_output.keys() - self._pcmd.keys():  # sent (BK-12: not with a command)
            del self._alarm_output[ring_position]
        self._pcmd.clear()
        replan = bool(self._branch) or self._reconfigure
        if self._branch:  # BK-46: no frame while the BKs switch their lines (BK-47)
            self.ring.idle(wire.branch_switch_pause_bits(len(config)) / self.ring.bit_rate)
        self._branch.clear()
        self._reconfigure = False
        messages = self._take_alarms(registers, sent=True, optical=optical) + self._messages(registers)
        self._record(messages)
        if replan:  # a branch switched, or a reconfiguration request acknowledged: read the configuration anew
            self._set_config(None)
        return CycleResult(Cycle.ID, True, messages)

    # -- internals -----------------------------------------------------------------------------------------------

    def _require_running(self) -> None:
        if self.stopped:
            raise InterbusError("docs/interbus.md, Configuration changes", "rediscover=False",
                                "the configuration changed and the master waits for start()")  # fmt: skip

    def _require_config(self) -> tuple[ConfigEntry, ...]:
        if self.config is None:
            raise InterbusError("docs/interbus.md, Master", None, "no configuration: run an ID cycle first")
        return self.config

    def _command(self, ring_position: int, optical: bool) -> int:
        code = self._watchdog_code if self._watchdog_pending else None
        alarm_output = None if ring_position in self._pcmd else self._alarm_output.get(ring_position)
        return wire.command_word(code, ring_position in self._quit, self._pcmd.get(ring_position),
                                 ring_position in self._alarm_request,
                                 self._branch.get(ring_position, BranchControl.NONE), optical,
                                 alarm_output)  # fmt: skip

    @property
    def _answering(self) -> set[int]:
        """Ring positions that send an answer in place of their ID code in the next ID cycle (A18, BK-5, OPT-50)."""
        return self._alarm_expected | self._optical_expected

    def _forget_positions(self) -> None:
        """A configuration read anew (A19): the records kept by ring position (branch status, processor alarms, MAU
        warnings) are dropped, as a position may now hold another device; a MAU warning on is asked again."""
        self.branch_status.clear()
        self.processor_alarms.clear()
        self._forget_optical(True)

    def _forget_optical(self, ask_again: bool) -> None:
        """A new configuration: forget the MAU warnings and requests by ring position; ``ask_again``: ask every
        device once if a warning was on, since positions may have moved (OPT-52)."""
        known = any(any(mau) for mau in self.mau_warnings.values())
        self.mau_warnings.clear()
        self._optical_request.clear()
        self._optical_expected.clear()
        self._explain.clear()
        if ask_again and known:
            self._optical_request.update(_optical(self.config or ()))

    def _set_config(self, config: tuple[ConfigEntry, ...] | None) -> None:
        self.config = config
        self._alarm_output.clear()  # by ring position, which a new configuration may move (BK-12)
        entries = config or ()
        total = sum(e.data_bytes for e in entries)
        self._out = bytearray(wire.LOOPBACK_BYTES_ON_LINE + bytes(total))
        self._in = bytes(total)
        self._in_slices, self._out_slices = [], []
        after = total
        for entry in entries:
            after -= entry.data_bytes
            self._in_slices.append(slice(after, after + entry.data_bytes))
            start = wire.LOOPBACK_BYTES + after
            self._out_slices.append(slice(start, start + entry.data_bytes))

    def _discovery(self) -> CycleResult:
        filler = bytes([wire.DISCOVERY_FILLER]) * (2 * self.max_devices)
        transfer = self.ring.transfer(Cycle.ID, wire.LOOPBACK_BYTES_ON_LINE + filler)
        problem = self._check(transfer, None)
        config: tuple[ConfigEntry, ...] | None = None
        registers: list[int] = []
        if problem is None:
            assert transfer.returned is not None
            devices = _find_loopback(transfer.returned) // 2
            registers = _id_registers(transfer.returned, devices)
            config, problem = _configuration(registers)
        self.ring.finish(transfer, problem is None)
        if problem is not None:
            return self._failed(Cycle.ID, problem)
        self._set_config(config)
        self.stopped = self._recover = False
        self._forget_positions()
        messages = self._messages(registers)
        self._record(messages)
        return CycleResult(Cycle.ID, True, messages)

    def _check(self, transfer: Transfer, loopback_at: int | None) -> Diagnostic | None:
        """The master's checks of a returned frame; ``loopback_at=None`` searches for the loopback word."""
        n = transfer.devices
        if transfer.returned is None:
            return Diagnostic(ErrorKind.DEAD_LINE, None, None, None, "no telegram came back")
        if transfer.receiver_error is not None:
            # Only a ring whose return line N + 1 is one line into the master (the transaction-level Ring) pins a
            # receiver error there; at pin level the return path runs through every chip, so it is located anew.
            # Nor does a frame cut where a BK switched its branch into it (BK-54, BK-56).
            where = n + 1 if getattr(self.ring, "direct_return_line", False) and not transfer.spliced else None
            return Diagnostic(transfer.receiver_error, where, None, None, "error on the return line")
        if transfer.flags.error:
            return Diagnostic(ErrorKind.TRANSMISSION, None, None, None, "CNTR came back with ERR set")
        returned = transfer.returned
        if loopback_at is None:
            if _find_loopback(returned) < 0:
                return Diagnostic(ErrorKind.LOOPBACK, None, None, None, "loopback word did not come back")
        elif returned[loopback_at : loopback_at + wire.LOOPBACK_BYTES] != wire.LOOPBACK_BYTES_ON_LINE:
            return Diagnostic(ErrorKind.LOOPBACK, None, None, None,
                              f"loopback word not at byte {loopback_at} of the returned data")  # fmt: skip
        return None

    def clear_diagnostics(self) -> None:
        """Forget every diagnostic kept so far (:attr:`diagnostics` and :attr:`dropped_diagnostics`)."""
        self.diagnostics.clear()
        self.dropped_diagnostics = 0

    def _record(self, found: Collection[Diagnostic]) -> None:
        """Keep ``found`` in :attr:`diagnostics`, dropping the oldest beyond ``max_diagnostics`` (A20)."""
        self.diagnostics.extend(found)
        excess = len(self.diagnostics) - self.max_diagnostics
        if excess > 0:
            del self.diagnostics[:excess]
            self.dropped_diagnostics += excess

    def _failed(self, cycle: Cycle, problem: Diagnostic) -> CycleResult:
        # TE bits are trusted only if a full-ring ID cycle was latched since the previous failed cycle: until then
        # a device may still hold TE from the earlier error (a data cycle does not clear TE in every device).
        trusted = not self._recover
        self._recover = True
        if problem.kind is not ErrorKind.CONFIGURATION and problem.location is None and self.config:
            if self.locate:
                problem = self._locate(problem, trusted)
            elif cycle is Cycle.ID and problem.kind is ErrorKind.LOOPBACK:
                # A25: the loopback word missing from an ID cycle over the table, the ring may be longer; without
                # location only a configuration difference the rescan finds is reported, else the failure stands
                found = self._rescan(problem, trusted)
                problem = found if found is not None and found.kind is ErrorKind.CONFIGURATION else problem
        located = self._with_device(problem)
        if problem.kind is ErrorKind.CONFIGURATION and self.config is not None:
            # A configuration difference: the table is dropped (A19); rebuilt by the next cycle() or by start(). The
            # commands not yet sent and the PF bits reported name ring positions a new table may give other devices:
            # dropped with it, so a PF standing on the new table is reported there (A19).
            self._set_config(None)
            self.stopped = not self.rediscover
            for pending in (self._quit, self._pcmd, self._alarm_request, self._branch, self._pf_active):
                pending.clear()
        self._record((located,))
        return CycleResult(cycle, False, (located,))

    def _with_device(self, d: Diagnostic) -> Diagnostic:
        config = self.config or ()
        device = config[d.location - 1].number if d.location is not None and d.location <= len(config) else None
        return Diagnostic(d.kind, d.location, device, d.code, d.detail, d.return_line, d.mau)

    def _locate(self, problem: Diagnostic, trusted: bool) -> Diagnostic:
        """Locate the error of a failed cycle: read the TE bits in a diagnostic ID cycle; if the ring answers
        with another configuration, report that; else search segment by segment (docs/interbus.md)."""
        config = self._require_config()
        n = len(config)
        data = wire.LOOPBACK_BYTES_ON_LINE + bytes(2 * n)
        transfer = self.ring.transfer(Cycle.ID, data)
        registers: list[int] = []
        check = self._check(transfer, 2 * n)
        if check is None:
            assert transfer.returned is not None
            registers = _id_registers(transfer.returned, n)
            check = _compare(config, registers, self._answering)
        self.ring.finish(transfer, check is None)
        if check is None:
            self._recover = False
            self._record(self._take_alarms(registers, sent=False) + self._messages(registers))
            return _from_te(problem, registers, "diagnostic ID cycle", trusted)
        if check.kind is ErrorKind.CONFIGURATION:
            return _changed(problem, check.location, check.detail)
        if check.kind is ErrorKind.LOOPBACK:
            found = self._rescan(problem, trusted)
            if found is not None:
                return found
        return self._search(problem)

    def _rescan(self, problem: Diagnostic, trusted: bool) -> Diagnostic | None:
        """A discovery-sized ID cycle after the loopback word went missing: if it passes, the ring answers with
        another device count (a configuration error at the first position that differs) or the error has gone
        (the TE bits locate it); ``None`` if it fails too."""
        config = self._require_config()
        filler = bytes([wire.DISCOVERY_FILLER]) * (2 * self.max_devices)
        transfer = self.ring.transfer(Cycle.ID, wire.LOOPBACK_BYTES_ON_LINE + filler)
        check = self._check(transfer, None)
        registers: list[int] = []
        if check is None:
            assert transfer.returned is not None
            registers = _id_registers(transfer.returned, _find_loopback(transfer.returned) // 2)
        self.ring.finish(transfer, check is None)
        if check is not None:
            return None
        self._recover = False
        where = _first_difference(config, registers, self._answering)
        if where is not None:
            return _changed(problem, where, f"{len(registers)} devices answer, the table has {len(config)}")
        self._record(self._take_alarms(registers, sent=False) + self._messages(registers))
        return _from_te(problem, registers, "discovery-sized ID cycle", trusted)

    def _search(self, problem: Diagnostic) -> Diagnostic:
        """Segment search: the smallest *j* for which the ring, closed after position *j* (*N* + 1: the whole ring
        with its return line), fails; then the same probe again, so a fault that went away in between is
        reported as not located rather than at a wrong position (docs/interbus.md, "Error location")."""
        n = len(self._require_config())
        if not getattr(self.ring, "closes_early", False):
            return _not_located(problem, "this ring cannot be closed early for a segment search")
        low, high = 1, n + 1
        while low < high:
            middle = (low + high) // 2
            failed = self._probe(middle)
            if failed is not None and failed.kind is ErrorKind.CONFIGURATION:
                return _changed(problem, failed.location, failed.detail)
            if failed is None:
                low = middle + 1
            else:
                high = middle
        failed = self._probe(low)
        if failed is None:
            return _not_located(problem, "the error went away during the segment search")
        if failed.kind is ErrorKind.CONFIGURATION:
            return _changed(problem, failed.location, failed.detail)
        if low == n + 1 and failed.kind is ErrorKind.LOOPBACK and self.max_devices < wire.MAX_DEVICES:
            # M31: devices added behind the last one, beyond the discovery window (max_devices), keep the loopback
            # word from coming back as a fault on the return line does: nothing proves the return line.
            return _not_located(problem, f"the loopback word is missing behind device {n}: a fault on the return "
                                f"line or more devices than max_devices ({self.max_devices})")  # fmt: skip
        where = "the return line" if low == n + 1 else f"the ring fails when closed after position {low}"
        problem = Diagnostic(problem.kind, low, None, None, f"{problem.detail}; segment search: {where}")
        return self._counted(problem, low) if failed.kind in COUNTED_KINDS else problem

    def _counted(self, problem: Diagnostic, low: int) -> Diagnostic:
        """An interrupt the segment search put at ``low`` inside a BK-LBD's branch: the BK's count of the counter
        telegram gives the exact line (2.2.2, BK-7); the search and the count must agree, else not located.
        Outside such a branch ``problem`` stands as the search found it. Only a probe that found an interrupt
        asks the count (:data:`COUNTED_KINDS`, BK-62)."""
        config = self._require_config()
        for entry in config:
            at = entry.ring_position
            branch = list(takewhile(lambda e: e.interface is InterfaceType.LOCAL_BUS, config[at:]))
            if entry.id_code != BK_LBD_ID_CODE or not at < low <= at + len(branch):
                continue
            kind = BranchKind.LBD_OR if all(e.id_code in LBD_OR_ID_CODES for e in branch) else BranchKind.LBD_MR
            self.branch_status.pop(at, None)
            if self._probe(at, ask=at) is not None or self._probe(at) is not None or at not in self.branch_status:
                return _not_located(problem, f"the branch status of BK {entry.number} could not be read")
            count = self.branch_status[at].counter
            found = lbd_position(kind, len(branch), count)
            if found is None or at + found[0] + found[1] != low:
                return _not_located(problem, f"BK {entry.number} counted {count}, which fits no break the segment "
                                    f"search allows ({kind.value} branch of {len(branch)} devices)")  # fmt: skip
            k, back = found
            line = f"the {'return' if back else 'forward'} line into {'the BK' if k == 0 else f'device {k}'}"
            return Diagnostic(problem.kind, at + k, None, None,
                              f"{problem.detail}; device-oriented local-bus diagnostics: BK {entry.number} counted "
                              f"{count} ({kind.value}): {line}", back)  # fmt: skip
        return problem

    def _probe(self, closed: int, ask: int | None = None) -> Diagnostic | None:
        """An ID cycle with the ring closed after ring position ``closed`` (N + 1: the whole ring); ``None`` if it
        passes, else what failed (a configuration difference: the ring changed under the search). Every probe
        sends the frame of the diagnostic ID cycle (2 N bytes), so a fault that depends on where in the frame it
        hits acts alike on every probe that crosses its line."""
        config = self._require_config()
        n = len(config)
        devices = min(closed, n)
        words = bytearray(2 * n)
        if ask is not None:  # a status request to the BK at ``ask`` (BK-5), answered in the next probe
            words[2 * (n - ask) : 2 * (n - ask) + 2] = wire.word_bytes(wire.command_word(alarm_request=True))
        data = wire.LOOPBACK_BYTES_ON_LINE + bytes(words)
        transfer = self.ring.transfer(Cycle.ID, data, None if closed > n else closed)
        problem = self._check(transfer, 2 * devices)
        if problem is None:
            assert transfer.returned is not None
            registers = _id_registers(transfer.returned, devices)
            problem = _compare(config[:devices], registers, self._answering)
        self.ring.finish(transfer, problem is None)
        if problem is None:
            self._record(self._take_alarms(registers, sent=False))
            if ask is not None:
                self._alarm_expected.add(ask)
            if closed > n:
                self._recover = False
        return problem

    def _take_alarms(self, registers: list[int], sent: bool,
                     optical: Collection[int] = ()) -> tuple[Diagnostic, ...]:  # fmt: skip
        """After a latched ID cycle: the devices asked in the previous one sent their processor alarm (a BK without
        µP: its branch status, BK-5) or their optical status (OPT-50) in place of the ID code; the requests this one
        carried (``sent``; ``optical``: the optical ones) are answered in the next (A18). Returns the BKs' reports
        (reconfiguration requests, branches they closed) and the MAU warnings that changed."""
        terminals = _terminals(self.config or ())
        found: list[Diagnostic] = []
        for position in sorted(self._optical_expected):
            if position <= len(registers):
                found += self._mau_report(position, registers[position - 1] & 0xFF)
        for position in sorted(self._alarm_expected):
            if position > len(registers):
                continue
            if position in terminals:
                found += self._branch_report(position, wire.decode_bk_status(registers[position - 1] & 0xFF))
            else:
                self.processor_alarms[position] = registers[position - 1] & 0xFF
        answered = range(1, len(registers) + 1)
        self._alarm_expected = set(self._alarm_request) if sent else self._alarm_expected.difference(answered)
        self._optical_expected = set(optical) if sent else self._optical_expected.difference(answered)
        if sent:
            self._alarm_request.clear()
            self._optical_request.difference_update(optical)
        return tuple(self._with_device(d) for d in found)

    def _branch_report(self, position: int, status: wire.BkStatus) -> list[Diagnostic]:
        """A BK's branch status read: report a reconfiguration request and a branch the BK closed, and acknowledge
        them in the next ID cycle (0714h, BK-8); a reconfiguration request makes the master read the configuration
        anew once acknowledged."""
        self.branch_status[position] = status
        found: list[Diagnostic] = []
        if status.conf_request:
            found.append(Diagnostic(ErrorKind.RECONFIGURATION_REQUEST, position, None, None,
                                    "CONF rose: reconfiguration request, acknowledged (2.4)"))  # fmt: skip
            self._reconfigure = True
        if status.closed:
            found.append(Diagnostic(ErrorKind.BRANCH_CLOSED, position, None, None,
                                    "the bus terminal module closed its branch: its return line was silent "
                                    "(extended BK function, 2.4)"))  # fmt: skip
        if found:
            self._quit.add(position)
        elif position in self._explain:  # asked after ATTN, and the branch has no report: the BK's optics (OPT-50)
            self._optical_request.add(position)
        self._explain.discard(position)
        return found

    def _mau_report(self, position: int, byte: int) -> list[Diagnostic]:
        """A device's optical status read: report every MAU warning that came on or went off (OPT-52)."""
        status = wire.decode_optical_status(byte)
        if status is None:  # the device does not know the request: it sent its ID code
            return []
        before = self.mau_warnings.get(position, (False, False, False))
        if any(status):
            self.mau_warnings[position] = status
        else:
            self.mau_warnings.pop(position, None)
        return [Diagnostic(ErrorKind.MAU_WARNING, position, None, MSG_MAU_WARNING,
                           f"{name} {'on' if on else 'off'}: the transmission reserve of the {where} "
                           f"{'is critical' if on else 'is back'} (1.6.3)", mau=(name, on))
                for name, where, on, was in zip(wire.MAU_WARNINGS, _MAU_PLACES, status, before, strict=True)
                if on != was]  # fmt: skip

    def _messages(self, registers: list[int]) -> tuple[Diagnostic, ...]:
        """Report the management bits of a latched ID cycle: PF as 0BB1h (once per fault), WD as 0C6Bh."""
        found: list[Diagnostic] = []
        for k, word in enumerate(registers, 1):
            if (word >> wire.MGMT_PF_BIT) & 1:
                if k not in self._pf_active:
                    self._pf_active.add(k)
                    found.append(Diagnostic(ErrorKind.PERIPHERAL_FAULT, k, None, MSG_PERIPHERAL_FAULT,
                                            "I/O device error indication (/StatErr)"))  # fmt: skip
            else:
                self._pf_active.discard(k)
            if (word >> wire.MGMT_WD_BIT) & 1:
                found.append(Diagnostic(ErrorKind.WATCHDOG, k, None, MSG_WATCHDOG,
                                        "layer-2 watchdog reset the process data"))  # fmt: skip
        if self._attention and not found and self.config is not None:
            # ATTN that no PF or WD bit explains: a BK has a report, its branch status tells (BK-5); or a MAU
            # warning changed: the optical status of the others tells, a BK's after its branch status (OPT-50)
            terminals = _terminals(self.config)
            self._alarm_request.update(terminals)
            self._explain.update(terminals)
            self._optical_request.update(_optical(self.config) - terminals)
        self._attention = False
        return tuple(self._with_device(d) for d in found)


def _terminals(config: tuple[ConfigEntry, ...]) -> set[int]:
    """Ring positions of the BKs without µP, which answer a status request with their branch status (BK-5)."""
    return {entry.ring_position for entry in config if entry.id_code in STATUS_TERMINAL_ID_CODES}


_MAU_PLACES: Final = ("incoming interface", "outgoing interface", "branch interface")
"""Where each MAU warning of ``wire.MAU_WARNINGS`` belongs (1.6.3)."""


def _optical(config: tuple[ConfigEntry, ...]) -> set[int]:
    """Ring positions the master may ask for their optical status: those whose ID code cannot be taken for an
    optical status byte (OPT-51)."""
    return {entry.ring_position for entry in config if wire.decode_optical_status(entry.id_code) is None}


def _find_loopback(returned: bytes) -> int:
    """Offset of the first word-aligned loopback word in ``returned``, -1 if there is none."""
    for at in range(0, len(returned) - 1, 2):
        if returned[at : at + 2] == wire.LOOPBACK_BYTES_ON_LINE:
            return at
    return -1


def _id_registers(returned: bytes, devices: int) -> list[int]:
    """The ID registers in ring order: device N's register comes back first."""
    return [wire.word_from_bytes(returned[2 * (devices - k) : 2 * (devices - k) + 2]) for k in range(1, devices + 1)]


def _configuration(registers: list[int]) -> tuple[tuple[ConfigEntry, ...] | None, Diagnostic | None]:
    """Build the configuration table from ID registers in ring order."""
    entries: list[ConfigEntry] = []
    segment, position = 0, 0
    for k, word in enumerate(registers, 1):
        id_code, length_code = word & 0xFF, (word >> 8) & 0x1F
        bits = LENGTH_CODE_BY_VALUE[length_code].bits
        if bits is None:
            return None, Diagnostic(ErrorKind.CONFIGURATION, k, None, None,
                                    f"reserved length code {length_code:05b}b (Table 3-11)")  # fmt: skip
        interface = interface_type(id_code)
        if interface is InterfaceType.LOCAL_BUS:
            position += 1
        else:
            segment, position = segment + 1, 0
        entries.append(ConfigEntry(k, segment, position, id_code, length_code, bits, wire.data_bytes(length_code),
                                   interface, _ID_ROWS.get(id_code), id_code in UP_NOT_READY_ID_CODES))  # fmt: skip
    return tuple(entries), None


def _compare(config: tuple[ConfigEntry, ...], registers: list[int], alarms: Collection[int]) -> Diagnostic | None:
    """The first device whose ID code or length code differs from the configuration; devices in ``alarms``
    send their processor alarm in place of the ID code (A18), so only their length code is compared."""
    for entry, word in zip(config, registers, strict=True):
        id_code = entry.id_code if entry.ring_position in alarms else word & 0xFF
        if (id_code, (word >> 8) & 0x1F) != (entry.id_code, entry.length_code):
            return Diagnostic(ErrorKind.CONFIGURATION, entry.ring_position, None, None,
                              f"ID register {word:04X}h differs from the configuration")  # fmt: skip
    return None


def _first_difference(config: tuple[ConfigEntry, ...], registers: list[int], alarms: Collection[int]) -> int | None:
    """The first ring position whose device differs from the table (ID code, length code, or present in one
    and not the other), ``None`` if the ring answers exactly with the table (A18 alarms compare length only)."""
    for entry, word in zip(config, registers, strict=False):
        id_code = entry.id_code if entry.ring_position in alarms else word & 0xFF
        if (id_code, (word >> 8) & 0x1F) != (entry.id_code, entry.length_code):
            return entry.ring_position
    if len(registers) != len(config):
        return min(len(registers), len(config)) + 1
    return None


def _fewer(config: tuple[ConfigEntry, ...], returned: bytes, alarms: Collection[int]) -> Diagnostic | None:
    """A25: the loopback word of an ID cycle over the table came back word-aligned after fewer ID registers than the
    table has (CRC and CNTR good): the ring has that many devices (no ID register can imitate the loopback word, A5),
    a configuration error at the first position that differs (A19); ``None`` if the loopback word is not there."""
    at = _find_loopback(returned)
    if not 0 <= at < 2 * len(config):
        return None
    registers = _id_registers(returned, at // 2)
    where = _first_difference(config, registers, alarms)
    return Diagnostic(ErrorKind.CONFIGURATION, where, None, None,
                      f"loopback word after {at // 2} ID registers, the table has {len(config)}: configuration "
                      f"changed at ring position {where}")  # fmt: skip


def _changed(problem: Diagnostic, position: int | None, detail: str) -> Diagnostic:
    """The configuration error that explains a failed cycle (docs/interbus.md, "Configuration changes")."""
    return Diagnostic(ErrorKind.CONFIGURATION, position, None, None,
                      f"{problem.detail}; configuration changed at ring position {position}: {detail}")  # fmt: skip


def _from_te(problem: Diagnostic, registers: list[int], how: str, trusted: bool) -> Diagnostic:
    """Locate ``problem`` by the lowest TE bit in a latched ID cycle, or report it not located; TE bits that may
    be left from an earlier error (``trusted=False``) locate nothing."""
    te = [k for k, word in enumerate(registers, 1) if (word >> wire.MGMT_TE_BIT) & 1]
    if te and not trusted:
        return Diagnostic(problem.kind, None, None, None,
                          f"{problem.detail}; not located: the {how} passed, and its TE bits may be left from an "
                          "earlier error (no ID cycle was latched since)")  # fmt: skip
    if te:
        return Diagnostic(problem.kind, te[0], None, None, f"{problem.detail}; TE bit read in a {how}")
    return Diagnostic(problem.kind, None, None, None,
                      f"{problem.detail}; not reproducible: the {how} passed and no device reports TE")  # fmt: skip


def _not_located(problem: Diagnostic, why: str) -> Diagnostic:
    """``problem`` reported as not located, with the reason."""
    return Diagnostic(problem.kind, None, None, None, f"{problem.detail}; not located: {why}")
