"""The firmware test bench: INTERBUS master, ring, SUPI 3 chip and firmware on one clock (transaction level).

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4.14 (interrupts, I/O access bit, latch phase, Figure 3-22), Table 3-7 (byte
times); decisions FW-1 to FW-6 and FW-14 in docs/assumptions/sdk.md; guide docs/sdk.md, "Firmware tests".

One clock, :attr:`Bench.now` (seconds), is bus time and firmware time at once:

- every byte the firmware clocks costs its Table 3-7 time at the firmware's SCLK (:func:`supi3.timing.upif_byte_s`),
  and its ``delay_us`` costs what it says; before each byte's /SS edges the bus catches up with the clock;
- the master starts a cycle every :attr:`Bench.cycle_time_s` (or back to back); a cycle loads the devices' IN data
  at its start and latches at its end, and in between, in a data cycle, the I/O access bit turns 1 when the check
  sequence begins and the latch phase runs over the last latch telegram (:func:`supi3.interbus.wire.cycle_phases`);
- a falling edge of /IRQ calls the firmware's :meth:`Firmware.isr`, at the next point where the firmware may be
  interrupted: when it is idle, or when a driver call of its main code has ended (FW-3).
- a run ends once the firmware has served its last cycle: for a firmware with a main loop, a whole pass of it after
  that cycle and the last service routine (FW-14), the emulated board's rule (MCU-30), defined once here
  (:class:`MainLoopPasses`).

So the interrupt method, the polling method with its 30-bit window and a firmware that touches the data registers
in the latch phase (``InconsistentDataError``) are all tested at transaction level.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable, Sequence
from types import TracebackType
from typing import Final, Literal, NamedTuple

from supi3 import tables, timing
from supi3.checks import check_bool, check_instance, check_int, check_real, describe, fail
from supi3.config import DeviceConfig, decode
from supi3.errors import Supi3Error
from supi3.interbus import wire
from supi3.interbus.link import Device
from supi3.interbus.master import CycleResult, Master
from supi3.interbus.ring import Branch, Bus, Ring, Transfer
from supi3.interbus.wire import Cycle
from supi3.model.chip import Supi3, clocks
from supi3.model.registers import RegisterFile
from supi3.sdk.driver import DriverArgumentError, Mode, Supi3Driver
from supi3.sdk.transports import ModelTransport

__all__ = [
    "DEFAULT_STRAPS",
    "SERVE_PASSES",
    "SERVE_TELEGRAMS",
    "START_WAIT_S",
    "Bench",
    "BenchError",
    "BenchTransport",
    "CycleTiming",
    "Firmware",
    "MainLoopPasses",
    "MasterStart",
    "ServeWait",
    "bench_config",
    "check_cycle_time",
    "check_run_cycles",
    "check_run_seconds",
    "default_config",
    "discovery_master",
    "resume_s",
    "ring_positions",
    "serve_wait_s",
    "telegram_end_s",
]

DEFAULT_STRAPS: Final[tuple[str, str]] = ("10011", "1110")
"""C[4..0] and MFP[15..12] of the bench's default chip: a remote bus device in the Init-µP mode (Table 2-4)."""
PIN_READ_S: Final[float] = 0.25e-6
"""FW-9: one read of a status pin (C/D, /IRQ, I/O) by the firmware, about 12 CPU clocks of a 48 MHz MCU."""
KEPT: Final[int] = 1000
"""FW-6: how many cycles :attr:`Bench.results` and :attr:`Bench.timeline` keep (a long run stays bounded)."""
IDLE_LOOPS_LIMIT: Final[int] = 1000
"""FW-5: main-loop calls in a row that clock no byte and wait for nothing before the bench calls it stuck."""
SERVE_TELEGRAMS: Final[int] = 64
"""MCU-30, FW-14: after a run's last master cycle, the wait for the main loop's pass (:class:`MainLoopPasses`) lasts
at most this many status telegrams' bus time (:func:`serve_wait_s`), on the firmware bench and on the emulated
board at either fidelity; at pin level the board also idles the line up to this many status telegrams while its
firmware is in a handler or has an /IRQ edge to serve (MCU-17)."""
SERVE_PASSES: Final[int] = 2
"""MCU-30, FW-14: arrivals at the main loop's idle point that make a whole pass: its entry and the next one."""


START_WAIT_S: Final[float] = 1e-3
"""MCU-17, MCU-45, FW-15: the latest bus time after power-up at which the master starts (Alarm Stop, discovery ID
cycle), if the firmware's set-up has not ended before (:class:`MasterStart`)."""


class MasterStart:
    """MCU-45, FW-15: when the master starts (its Alarm Stop and discovery ID cycle), the one rule of the firmware
    bench (:class:`Bench`) and the emulated board at both fidelities (``supi3.mcu.board.Board``).

    The master waits for the firmware's set-up, so that its first ID cycle reads the configuration the firmware
    writes (3.4.3: SET and ID), not the chip's reset values: the line idles in status telegrams up to :attr:`at`,
    the bus time the runner said the set-up ended (:meth:`set_up`), at the latest :data:`START_WAIT_S` after
    power-up (a firmware that never says so), and the master starts at the end of that telegram (:meth:`start_s`).
    The set-up has ended when the firmware first waits for the bus or first comes to its main loop's idle point: on
    the board, the core's first sleep (WFI, WFE, a thread-mode ``b .``, MCU-4) or its first arrival at ``fw_loop``
    (MCU-30); on the firmware bench, :meth:`Bench.power_up` (the firmware's :meth:`Firmware.setup` returned, or the
    test's own driver calls before its first run). Times are bus seconds since power-up.
    """

    __slots__ = ("set_up_at",)

    def __init__(self) -> None:
        self.set_up_at: float | None = None
        """When the firmware's set-up ended; ``None``: not yet."""

    @property
    def at(self) -> float:
        """The bus time the master starts: the set-up's end, at the latest :data:`START_WAIT_S`."""
        set_up = self.set_up_at
        return START_WAIT_S if set_up is None or set_up > START_WAIT_S else set_up

    def set_up(self, at: float) -> bool:
        """The firmware's set-up ended at ``at`` (only the first call counts); whether this call noted it.

        Raises
        ------
        ArgumentError
            ``at`` not a finite number >= 0.
        """
        if self.set_up_at is not None:
            return False
        self.set_up_at = check_real("at", at, 0.0)
        return True

    def due(self, now: float) -> bool:
        """Whether the master starts at bus time ``now`` (at or after :attr:`at`).

        Raises
        ------
        ArgumentError
            ``now`` not a number >= 0 (NaN was never due: the master never started).
        """
        if not (type(now) is float and now >= 0.0):  # the board asks every status telegram: one test when valid
            now = check_real("now", now, 0.0, finite=False)
        return now >= self.at

    def start_s(self, bit_rate: int) -> float:
        """The bus time the master starts on a line that idles in whole status telegrams from power-up: the end of
        the telegram in which :attr:`at` falls (the pin-level board's telegrams, checked with :meth:`due`, end
        there too)."""
        return telegram_end_s(0.0, self.at, bit_rate)


def telegram_end_s(since: float, at: float, bit_rate: int) -> float:
    """The end of the status telegram in which bus time ``at`` falls, on a line idling in whole status telegrams
    (:data:`~supi3.interbus.wire.STATUS_TELEGRAM_BITS` at ``bit_rate``) from ``since``; ``at`` itself if it is
    such an end (to a float's rounding), ``since`` if ``at`` is not after it.

    Raises
    ------
    ArgumentError
        ``since`` not a finite number >= 0, ``at`` not a finite number; ``bit_rate`` not one of Table 1-7's.
    """
    since = check_real("since", since, 0.0)
    at = check_real("at", at)
    telegram_s = wire.STATUS_TELEGRAM_BITS / wire.check_bit_rate(bit_rate)
    return since + max(0, math.ceil((at - since) / telegram_s - 1e-9)) * telegram_s


def discovery_master(bus: Bus, devices: int, *, locate: bool = True) -> Master:
    """MCU-56, FW-20: the master of the firmware bench (:class:`Bench`) and the emulated board at both fidelities
    (``supi3.mcu.board.Board``): its discovery ID cycle sized for the ``devices`` the ring holds (A14: two filler
    bytes a device), not for the largest ring (:data:`~supi3.interbus.wire.MAX_DEVICES`), so both fidelities power
    up in the same bus time (1.2 ms for ``run(3)`` of one chip at 500 kbit/s, not 27 ms). ``locate=False`` for a
    ring that cannot close early (the pin-level one, MCU-17).

    Raises
    ------
    ArgumentError
        ``devices`` not an integer from 1 to :data:`~supi3.interbus.wire.MAX_DEVICES`.
    """
    return Master(bus, locate=locate, max_devices=devices)


def ring_positions(devices: Sequence[Device | Branch]) -> int:
    """The ring positions of a ring of ``devices`` (a tree: each :class:`~supi3.interbus.ring.Branch` its bus
    terminal module and every device of its branch), the most its discovery ID cycle can find (MCU-56).

    Raises
    ------
    ArgumentError
        ``devices`` not a sequence of devices and branches.
    """
    if isinstance(devices, (str, bytes)) or not isinstance(devices, Sequence):
        raise fail("devices", "a sequence of devices and branches", devices)
    positions = 0
    for item in devices:
        if isinstance(item, Branch):
            positions += 1 + ring_positions(item.devices)
        elif isinstance(item, Device):
            positions += 1
        else:
            raise fail("devices", "a sequence of devices and branches", item, "an item is neither")
    return positions


class ServeWait:
    """MCU-55, FW-19: the end of a run of ``n`` master cycles, the one rule of the firmware bench (:meth:`Bench.run`)
    and the emulated board at both fidelities (``supi3.mcu.board.Board.run``).

    The master runs exactly the ``n`` cycles; from the last one's end (:meth:`begin`) the line idles in status
    telegrams (the master starts no cycle) while the firmware finishes: an interrupt handler active or pending, an
    /IRQ edge not yet taken, its main loop's pass to make (:class:`MainLoopPasses`). The wait lasts at most
    :func:`serve_wait_s` (:data:`SERVE_TELEGRAMS` telegrams) from that end, a handler's as a pass's (:meth:`over`):
    a run that reaches the bound ends there, unserved. The next run's first cycle starts at the end of the status
    telegram in which the run ended, or on the cycle time's schedule if that is later (:meth:`resume_s`). Times are
    bus seconds.
    """

    __slots__ = ("_half_s", "_wait_s", "ended")

    def __init__(self, bit_rate: int) -> None:
        self._wait_s = serve_wait_s(bit_rate)
        self._half_s = wire.STATUS_TELEGRAM_BITS / bit_rate / 2
        self.ended: float | None = None
        """When the run's last cycle ended; ``None``: no wait under way."""

    def begin(self, ended: float) -> float:
        """The run's last cycle ended at ``ended``: the wait's bound (:attr:`until`).

        Raises
        ------
        ArgumentError
            ``ended`` not a finite number >= 0.
        """
        self.ended = check_real("ended", ended, 0.0)
        return self.until

    @property
    def until(self) -> float:
        """The latest bus time the run ends: :func:`serve_wait_s` after the last cycle's end."""
        if self.ended is None:
            raise BenchError("ServeWait.until before begin (no run's last cycle has ended)")
        return self.ended + self._wait_s

    def over(self, now: float) -> bool:
        """Whether the wait has reached its bound at bus time ``now`` (to half a status telegram: the pin-level line
        idles in whole telegrams, whose float sum may fall an ulp short).

        Raises
        ------
        ArgumentError
            ``now`` not a number >= 0 (NaN was never over: the wait never ended).
        """
        if not (type(now) is float and now >= 0.0):
            now = check_real("now", now, 0.0, finite=False)
        return now >= self.until - self._half_s

    def end(self) -> None:
        """The run ended."""
        self.ended = None


def resume_s(since: float, scheduled: float, now: float, bit_rate: int) -> float:
    """MCU-55, FW-19: when the master's next cycle starts after a run that held it from ``since`` (the last cycle's
    end; 0 before the master's first cycle) and ended at ``now``: the end of the status telegram the line idled in
    then (:func:`telegram_end_s`), or ``scheduled`` (the cycle time's next start) if later.

    Raises
    ------
    ArgumentError
        ``scheduled`` not a number >= 0 (infinity: no schedule), or :func:`telegram_end_s`'s arguments.
    """
    return max(check_real("scheduled", scheduled, 0.0, finite=False), telegram_end_s(since, now, bit_rate))


def check_run_cycles(cycles: object, now: float, bit_rate: int, cycle_time_s: float | None = None) -> int:
    """A26: ``cycles``, the master cycles of a run from bus time ``now`` at ``bit_rate``, the one check of the firmware
    bench's :meth:`Bench.run` and the emulated board's run: an integer from 0, no more than fit before the bus
    time's maximum (no cycle is shorter than the shortest of a one-device ring, nor, on a ``cycle_time_s``
    schedule, than the cycle time: UP-48; a count too large for a float, 2**53 and more, is refused as that many).

    Raises
    ------
    ArgumentError
        ``cycles`` not an integer from 0, or more than fit before :data:`~supi3.interbus.wire.MAX_BUS_TIME_S`.
    """
    count = check_int("cycles", cycles, 0)
    shortest = max(wire.cycle_bits(0, 1) / wire.check_bit_rate(bit_rate), cycle_time_s or 0.0)
    wire.check_bus_time("cycles", cycles, now, min(count, 2**53) * shortest)
    return count


def check_cycle_time(cycle_time_s: object) -> float:
    """UP-48: a master's ``cycle_time_s`` on the firmware bench and the emulated board: a finite number of seconds from
    0 to the bus time's maximum (A26; 1e30 was taken, and the second cycle's start then raised inside the ring with
    the bench's clock already past the maximum).

    Raises
    ------
    ArgumentError
        ``cycle_time_s`` not a finite number from 0 to :data:`~supi3.interbus.wire.MAX_BUS_TIME_S`.
    """
    return check_real("cycle_time_s", cycle_time_s, 0.0, wire.MAX_BUS_TIME_S, limit="A26: the bus time's maximum")


def check_run_seconds(seconds: object, now: float) -> float:
    """A26: ``seconds``, the bus time a timed run from ``now`` lasts, the one check of the firmware bench's
    :meth:`Bench.run_for` and the emulated board's: a finite number >= 0 that does not take bus time past its
    maximum (1e30 s ran for ever).

    Raises
    ------
    ArgumentError
        ``seconds`` not a finite number >= 0, or past :data:`~supi3.interbus.wire.MAX_BUS_TIME_S` from ``now``.
    """
    value = check_real("seconds", seconds, 0.0)
    wire.check_bus_time("seconds", seconds, now, value)
    return value


def serve_wait_s(bit_rate: int) -> float:
    """MCU-30, FW-14: the longest wait for the main loop's pass after a run's last cycle at ``bit_rate``:
    :data:`SERVE_TELEGRAMS` status telegrams (0.64 ms at 500 kbit/s)."""
    return SERVE_TELEGRAMS * (wire.STATUS_TELEGRAM_BITS / wire.check_bit_rate(bit_rate))


class MainLoopPasses:
    """MCU-30, FW-14: when a firmware with a main loop has served a run's last cycle, the one rule of the firmware
    bench (:meth:`Bench.run`) and the emulated board (``supi3.mcu.board.Board.run``).

    The runner calls :meth:`begin` with the time it saw the run's last cycle end, :meth:`arrive` each time the
    firmware comes to its main loop's idle point (a pass's entry), :meth:`handler` each time an interrupt handler
    begins. The last cycle is served once a whole pass (:data:`SERVE_PASSES` arrivals, entry to entry) began at or
    after :attr:`since` and after the last handler: a handler forgets the arrivals before it, since a pass that
    began before it may have missed what the handler noted. Times are in the runner's unit (bench seconds, core
    cycles), only compared.
    """

    __slots__ = ("arrivals", "since")

    def __init__(self) -> None:
        self.since: float | None = None
        """When the run's last cycle was seen to end; ``None``: no wait under way (nothing is served)."""
        self.arrivals: tuple[float, ...] = ()
        """The last arrivals at the idle point (at most :data:`SERVE_PASSES`) since the last handler."""

    def begin(self, since: float) -> None:
        """The run's last cycle was seen to end at ``since``: the passes count from there.

        Raises
        ------
        ArgumentError
            ``since`` not a finite number, or before the last arrival (the runner's clock does not go back).
        """
        since = check_real("since", since)
        arrivals = self.arrivals
        if arrivals and since < arrivals[-1]:
            raise fail("since", f"a time at or after the last arrival ({arrivals[-1]})", since, "FW-14")
        self.since = since

    def end(self) -> None:
        """The wait is over (the run ended)."""
        self.since = None

    def handler(self) -> None:
        """An interrupt handler begins: passes count only from after it."""
        self.arrivals = ()

    def arrive(self, at: float) -> bool:
        """The firmware comes to its main loop's idle point at ``at``; whether that makes the run served.

        Raises
        ------
        ArgumentError
            ``at`` not a finite number, or before the last arrival or :attr:`since` (the clock does not go back).
        """
        at = check_real("at", at)
        arrivals, since = self.arrivals, self.since
        last = max(arrivals[-1] if arrivals else -math.inf, -math.inf if since is None else since)
        if at < last:
            raise fail("at", f"a time at or after the last arrival or the wait's begin ({last})", at, "FW-14")
        self.arrivals = (*arrivals[1 - SERVE_PASSES :], at)
        return self.passed()

    def passed(self) -> bool:
        """A whole pass began at or after :attr:`since` and after the last handler."""
        since, arrivals = self.since, self.arrivals
        return since is not None and len(arrivals) == SERVE_PASSES and arrivals[0] >= since


def bit_offset(bit: int, bit_s: float) -> float:
    """From a cycle's start to the mid-bit sample of its bit period ``bit`` (:meth:`CycleTiming.at`, A1)."""
    return (bit + 0.5) * bit_s


class CycleTiming(NamedTuple):
    """When one master cycle ran on the bench clock: its start (first bit), its kind and its phases."""

    start: float
    cycle: Cycle
    phases: wire.CyclePhases
    bit_s: float

    def at(self, bit: int) -> float:
        """The mid-bit sample of bit period ``bit`` (0 = the cycle's first): when the chip decides on it (A1).

        Raises
        ------
        ArgumentError
            ``bit`` not an integer >= 0.
        """
        if type(bit) is not int or bit < 0:
            bit = check_int("bit", bit, 0)
        return self.start + bit_offset(bit, self.bit_s)

    @property
    def io_busy(self) -> float:
        """A data cycle's I/O access bit turns 1 (the check sequence begins)."""
        return self.at(self.phases.check_bit)

    @property
    def latch(self) -> float:
        """A data cycle's latch phase begins."""
        return self.at(self.phases.latch_bit)

    @property
    def end(self) -> float:
        """The latch: OUT data and events appear, both phases end."""
        return self.at(self.phases.end_bit)


_NO_TIME: Final = -math.inf
_LAST_TIME: Final = wire.MAX_BUS_TIME_S
"""The bounds of :meth:`Bench.advance`'s one test of a valid time (A26), without an attribute lookup a call."""
_new_tuple: Final = tuple.__new__
"""A named tuple made from its fields in order, as its class's own ``__new__`` does, without that Python call (FW-27:
a :class:`CycleTiming` a master cycle)."""


class BenchError(Supi3Error, RuntimeError):
    """The bench cannot go on: the firmware is stuck, or the bus has nothing left to do."""


def default_config(bit_rate: int = 500_000) -> DeviceConfig:
    """The default chip: :data:`DEFAULT_STRAPS` at ``bit_rate`` (CLK_CONF of Table 1-7)."""
    return decode(*DEFAULT_STRAPS, clk_conf=tables.clk_conf_for(wire.check_bit_rate(bit_rate)))


def bench_config(config: DeviceConfig | None, bit_rate: int | None) -> DeviceConfig:
    """The chip's straps of a bench or board: ``config``, else :func:`default_config` at ``bit_rate`` (500 kbit/s if
    ``None``). A ``bit_rate`` given beside a ``config`` must be the config's: its CLK_CONF straps the rate (Table
    1-7), and a second rate would be ignored in silence."""
    if config is None:
        return default_config(500_000 if bit_rate is None else bit_rate)
    check_instance("config", config, DeviceConfig)
    if bit_rate is not None:
        wire.check_bit_rate(bit_rate)  # UP-48: 500000.0 or True beside a config as without one (refused by name)
    if bit_rate is not None and bit_rate != config.bit_rate:
        raise DriverArgumentError("bit_rate", bit_rate, f"bit_rate {bit_rate!r} is not the config's {config.bit_rate} "
                                  "bit/s (its CLK_CONF straps the rate, Table 1-7): give one of them")  # fmt: skip
    return config


class Firmware:
    """The firmware under test, as the bench calls it. Subclass and override what the firmware has.

    :meth:`setup` runs once at power-up, :meth:`isr` on each falling edge of /IRQ, and :meth:`loop` (if overridden)
    again and again as the main loop; a firmware without a main loop sleeps until its next interrupt.
    """

    def setup(self, drv: Supi3Driver) -> None:
        """Power-up: initialize the interface, configure SET and ID, enable interrupts."""
        del drv

    def isr(self, drv: Supi3Driver) -> None:
        """The /IRQ service routine."""
        del drv

    def loop(self, drv: Supi3Driver) -> None:
        """One pass of the main loop (polling firmware)."""
        del drv


class _ClockedBus:
    """The ring as the master sees it, except that the finish of a cycle (the latch) waits for the bench clock
    to reach the cycle's end; a second transfer in one master call (error location) finishes the first at once."""

    closes_early: Final = True
    direct_return_line: Final = True

    def __init__(self, ring: Ring) -> None:
        self.ring = ring
        self.pending: tuple[Transfer, bool, float] | None = None

    @property
    def now(self) -> float:
        return self.ring.now

    @property
    def bit_rate(self) -> int:
        return self.ring.bit_rate

    def flush(self) -> None:
        if self.pending is not None:
            transfer, latch, _ = self.pending
            self.pending = None
            self.ring.finish(transfer, latch)

    def transfer(self, cycle: Cycle, data: bytes, close_after: int | None = None) -> Transfer:
        if self.pending is not None:  # a second transfer in one master call
            self.flush()
        return self.ring.transfer(cycle, data, close_after)

    def finish(self, transfer: Transfer, latch: bool) -> None:
        self.pending = (transfer, latch, self.ring.now)

    def reset(self) -> None:
        self.flush()
        self.ring.reset()

    def idle(self, seconds: float) -> None:
        self.flush()
        self.ring.idle(seconds)


class BenchTransport(ModelTransport):
    """:class:`ModelTransport` on the bench clock: each byte and delay advances bus time (FW-1, FW-2)."""

    def __init__(self, bench: Bench, chip: Supi3) -> None:
        super().__init__(chip)
        self.bench = bench
        self._depth = 0

    def xfer(self, tx: int, s_r: bool) -> int:
        """One frame: the chip decides what it drives at /SS falling, takes the byte at /SS rising (UP-18, UP-19);
        the bus runs up to each edge."""
        bench = self.bench
        if bench._next_at <= bench.now:  # a bus event due now (else advance(now) would only compare)
            bench.advance(bench.now)
        driven = ModelTransport.xfer(self, tx, s_r)  # FW-28: not super(), which makes an object a byte
        bench.bytes_clocked += 1
        if not bench._irq_level:  # FW-18: a byte may release /IRQ (a read of IRQ_EVT), never pull it low
            bench.irq_edge()
        return driven

    def _during_frame(self) -> None:
        bench = self.bench
        until = bench.now + bench.byte_s
        if until < bench._next_at and until <= _LAST_TIME:  # advance's own test (FW-28: its constant)
            bench.now = until
        else:
            bench.advance(until)

    def delay_us(self, us: float) -> None:
        """Busy wait: the bus runs on."""
        bench = self.bench
        bench.advance(bench.now + check_real("us", us, 0.0) * 1e-6)

    def read_cd(self) -> int:
        """C/D, read in :attr:`Bench.pin_read_s` (FW-9)."""
        self.bench.advance(self.bench.now + self.bench.pin_read_s)
        return super().read_cd()

    def read_irq(self) -> int:
        """/IRQ, read in :attr:`Bench.pin_read_s` (FW-9)."""
        self.bench.advance(self.bench.now + self.bench.pin_read_s)
        return ModelTransport.read_irq(self)  # FW-28: a pin read or two a master cycle

    def read_io(self) -> int | None:
        """The I/O access bit, read in :attr:`Bench.pin_read_s`; ``None`` if the bench leaves the pin unwired
        (:attr:`Bench.io_pin`)."""
        if not self.bench.io_pin:
            return None
        self.bench.advance(self.bench.now + self.bench.pin_read_s)
        return super().read_io()

    def access(self) -> _Access:
        """A driver call: violations deferred to its end; an interrupt that came during a call of the main code is
        taken when it ends (FW-3)."""
        return _Access(self)


class _Access:
    __slots__ = ("_deferred", "_transport")

    def __init__(self, transport: BenchTransport) -> None:
        self._transport = transport
        self._deferred = transport.registers.violations.deferred()

    def __enter__(self) -> None:
        self._transport._depth += 1
        self._deferred.__enter__()

    def __exit__(self, kind: type[BaseException] | None, error: BaseException | None,
                 trace: TracebackType | None) -> Literal[False]:  # fmt: skip
        transport = self._transport
        transport._depth -= 1
        self._deferred.__exit__(kind, error, trace)
        if kind is None and transport._depth == 0:
            transport.bench.take_interrupt()
        return False


class Bench:
    """Master, ring, one SUPI 3 chip in an Init-µP mode and its firmware, on one clock (transaction level).

    Parameters
    ----------
    config:
        The chip's straps (an Init-µP mode); default :func:`default_config` at ``bit_rate``.
    firmware:
        What runs on the µP (:class:`Firmware`); ``None``: only the test drives :attr:`driver`.
    mode:
        The interface type the firmware uses (Table 3-8); tells the bench the Intel bit order, nothing more.
    bit_rate:
        INTERBUS bit rate when ``config`` is not given (500 kbit/s if neither is); given beside ``config``, it must
        be the config's (:func:`bench_config`).
    others:
        Further devices in the ring, behind the chip (ring positions 2, 3, ...).
    sclk_hz:
        The firmware's SCLK; default the fastest Table 3-7 allows.
    frame_gap_us:
        The driver's wait after each frame.
    cycle_time_s:
        The master starts a cycle this often (``None``: back to back, the fastest the ring allows).
    strict:
        Rule violations of the firmware raise (``True``) or are recorded in ``chip.registers.violations``.
    io_pin:
        The I/O access pin (MFP1) is wired to the firmware; ``False``: the driver polls D7 of IRQ_EVT instead, the
        manual's polling method (3.4.14), each poll clocking its two bytes.
    pin_read_s:
        What reading one of C/D, /IRQ or I/O costs the firmware (FW-9; default :data:`PIN_READ_S`).
    pedantic:
        Report legal but suspicious register accesses too (``SuspiciousAccessError``, UP-30 to UP-38).

    Attributes
    ----------
    chip, ring, master, driver, transport:
        The parts; tests may use each directly (calls on :attr:`driver` from a test act as the firmware's main code).
    now:
        The clock, seconds since power-up.
    cycles:
        Master cycles finished (ID and data).
    interrupts:
        Calls of :meth:`Firmware.isr`.
    irq_latency_s:
        The longest time from a falling edge of /IRQ to its service routine's first byte.
    results:
        The master's :class:`CycleResult` of every cycle started, the last :data:`KEPT` (FW-6).
    timeline:
        The :class:`CycleTiming` of every cycle started, the last :data:`KEPT`.
    served:
        The last :meth:`run` ended with the firmware's work served (FW-14).
    """

    def __init__(
        self,
        config: DeviceConfig | None = None,
        *,
        firmware: Firmware | None = None,
        mode: Mode = Mode.MOTOROLA,
        bit_rate: int | None = None,
        others: Sequence[Device] = (),
        sclk_hz: float | None = None,
        frame_gap_us: float = 0.0,
        cycle_time_s: float | None = None,
        strict: bool = True,
        io_pin: bool = True,
        pin_read_s: float = PIN_READ_S,
        pedantic: bool = False,
    ) -> None:
        self.config = bench_config(config, bit_rate)
        if firmware is not None and not isinstance(firmware, Firmware):
            raise DriverArgumentError("firmware", firmware, f"firmware must be a supi3.sdk.bench.Firmware, not "
                                      f"{describe(firmware)}")  # fmt: skip
        self.firmware = firmware
        self.mode = check_instance("mode", mode, Mode)
        self.chip = Supi3(self.config, strict=check_bool("strict", strict), pedantic=check_bool("pedantic", pedantic))
        if self.chip.registers is None:
            raise DriverArgumentError("config", config, f"config must strap an Init-µP mode (Tables 2-4 to 2-7), "
                                      f"not {self.config.function!r}")  # fmt: skip
        self.registers: RegisterFile = self.chip.registers
        if isinstance(others, str | bytes) or not isinstance(others, Sequence):  # Ring names each item's error
            raise fail("others", "a sequence of the devices behind the chip (Device objects)", others)
        self.byte_s = timing.upif_byte_s(self.config.bit_rate, sclk_hz)
        self.io_pin = check_bool("io_pin", io_pin)
        self.pin_read_s = check_real("pin_read_s", pin_read_s, 0.0, 1e-3)
        self.cycle_time_s = None if cycle_time_s is None else check_cycle_time(cycle_time_s)
        self.transport = BenchTransport(self, self.chip)
        self.driver = Supi3Driver(self.transport, frame_gap_us=frame_gap_us)
        # the ring last of what may refuse an argument: it claims its devices (UP-47), a refused bench holds none
        tree = [self.chip, *others]
        self.ring = Ring(tree, bit_rate=self.config.bit_rate)
        self._bus = _ClockedBus(self.ring)
        self.master = discovery_master(self._bus, ring_positions(tree))  # MCU-56, FW-20
        self._chips = [d for d in self.ring.devices if isinstance(d, Supi3) and d.registers is not None]
        self.now = 0.0
        self.cycles = 0
        self.bytes_clocked = 0
        self.interrupts = 0
        self.irq_latency_s = 0.0
        self.results: deque[CycleResult] = deque(maxlen=KEPT)
        self.timeline: deque[CycleTiming] = deque(maxlen=KEPT)
        self.registers.use_clock(lambda: clocks(self.now))
        self._bit_s = 1.0 / self.config.bit_rate
        self._events: list[tuple[float, str]] = []  # this cycle's phase changes, latest first
        self._start = MasterStart()  # MCU-45, FW-15: the master's first cycle waits for the set-up's end
        self._next_start = self._start.start_s(self.config.bit_rate)
        self._next_at = self._next_start  # the time of the next bus event: the last of _events, else _next_start
        # (data bytes, devices, return repeaters), their phases, and the end, latch and I/O bit's offsets from the
        # start (CycleTiming's end, latch, io_busy): worked out again only when the cycle's size changes
        self._phases = ((-1, -1, -1), wire.CyclePhases(0, 0, 0, 0), (0.0, 0.0, 0.0))
        self._started = False
        self._irq_level = 1
        self._irq_fell_at: float | None = None
        self._in_isr = False
        self._in_firmware: str | None = None  # the Firmware method the bench runs now ("setup", "loop"; isr: _in_isr)
        self._set_up = False
        self.served = True
        """FW-14: the last :meth:`run` ended with the firmware's work served (False: the wait for the main loop's
        pass ran out, or the run raised)."""
        self._passes = MainLoopPasses()
        self._wait = ServeWait(self.config.bit_rate)  # MCU-55, FW-19: the end of a run's wait
        self._hold: float = math.inf  # MCU-55, FW-19: the master starts no cycle once this many have ended
        self._held: tuple[float, float] | None = None  # held: (the next cycle's start as scheduled, the hold's since)

    # -- the bus side ------------------------------------------------------------------------------------------

    def advance(self, until: float) -> bool:
        """Run the bus up to time ``until`` and set the clock there (not backwards); whether a bus event (a cycle's
        start, phase or end) ran on the way: only then can the master's cycle have changed the chip.

        Raises
        ------
        ArgumentError
            ``until`` not a finite number (NaN would run nothing, infinity for ever), or past
            :data:`~supi3.interbus.wire.MAX_BUS_TIME_S` (A26); nothing changes.
        """
        if type(until) is not float or not _NO_TIME < until <= _LAST_TIME:  # the board's float: one test
            until = check_real("until", until)
            wire.check_bus_time("until", until, self.now, until - self.now)
        # Most calls (a byte, a pin read) find no bus event due: one comparison with the next event's time, kept by
        # _run_bus and _start_cycle (the board's synchronisation makes it without this call, FW-27).
        if self._next_at <= until:
            self._run_bus(until, False)
            if until > self.now:
                self.now = until
            return True
        if until > self.now:
            self.now = until
        return False

    def _run_bus(self, until: float, sleep: bool) -> None:
        """Run the bus events due by ``until`` in their order: a cycle starts, a phase begins, or the cycle ends.

        ``sleep``: the firmware sleeps (FW-18): only up to the next start or end, the events that may change /IRQ
        (it wakes at most there), and the phases on the way are not set: they only set the chip's I/O access bit and
        latch phase (MCU-31), which no one reads before the cycle's end, due in the same call, clears them."""
        while self._next_at <= until:
            events = self._events
            if not events:
                self._start_cycle()
                if sleep:
                    return
                continue
            at, what = events.pop()
            self._next_at = events[-1][0] if events else self._next_start
            if at > self.now:
                self.now = at
            if what == "io":
                if not sleep:
                    for chip in self._chips:
                        chip.set_io_access(True)
            elif what == "latch":
                if not sleep:
                    for chip in self._chips:
                        chip.set_latch_phase(True)
            else:
                self._bus.flush()
                for chip in self._chips:
                    chip.set_latch_phase(False)
                    chip.set_io_access(False)
                self.cycles += 1
                self.irq_edge()
                if sleep:
                    return

    def _start_cycle(self) -> None:
        if self.cycles >= self._hold:  # MCU-55, FW-19: the run's cycles are done, the line idles until it ends
            self._held = (self._next_start, self.timeline[-1].end if self.timeline else 0.0)
            self._next_start = self._next_at = math.inf
            return
        at = self._next_start
        if at > self.now:
            self.now = at
        if at > self.ring.now:
            self.ring.idle(at - self.ring.now)
        result = self.master.cycle() if self._started else self.master.start()
        self._started = True
        self.results.append(result)
        pending = self._bus.pending
        if pending is None:  # cannot happen: every master cycle ends with a finish
            raise BenchError("the master ran a cycle without finishing it")
        transfer, _, start = pending
        size = (len(transfer.sent) - wire.LOOPBACK_BYTES, transfer.devices, transfer.return_repeaters)
        if size != self._phases[0]:
            phases = wire.cycle_phases(*size)
            offsets = tuple(bit_offset(bit, self._bit_s) for bit in (phases.end_bit, phases.latch_bit,
                                                                       phases.check_bit))  # fmt: skip
            self._phases = (size, phases, (offsets[0], offsets[1], offsets[2]))
        _, phases, (to_end, to_latch, to_io) = self._phases
        self.timeline.append(_new_tuple(CycleTiming, (start, transfer.cycle, phases, self._bit_s)))
        end = start + to_end  # CycleTiming.end, .latch, .io_busy: the same sums
        events = [(end, "end"), (start + to_latch, "latch"), (start + to_io, "io")] \
            if transfer.cycle is Cycle.DATA else [(end, "end")]  # fmt: skip
        self._events = events
        self._next_start = end if self.cycle_time_s is None else max(end, start + self.cycle_time_s)
        self._next_at = events[-1][0]
        self.irq_edge()

    # -- the board's other pins -------------------------------------------------------------------------------

    def set_stat_err(self, active: bool) -> None:
        """The firmware drives /StatErr (3.6.2): ``True`` reports a peripheral fault (the chip latches it after its
        filter time and tells the master); ``False`` ends it."""
        self.advance(self.now)
        self.chip.set_stat_err(active, self.now)

    @property
    def mod_ack(self) -> int:
        """/ModAck now: 0 during its pulse after the master's Quit Peripheral Error (3.6.2), else 1."""
        self.advance(self.now)
        return 0 if clocks(self.now) < self.chip.mod_ack_until else 1

    @property
    def mod_ack_pulses(self) -> int:
        """/ModAck pulses so far (3.6.2): what an edge-triggered MCU input wired to /ModAck counts (the pulse is
        shorter than any firmware poll, M3)."""
        self.advance(self.now)
        return self.chip.events["MODACK"]

    # -- interrupts --------------------------------------------------------------------------------------------

    def irq_edge(self) -> None:
        """Watch /IRQ for a falling edge (FW-3: edge-triggered, as an MCU's external interrupt): after each cycle's
        start and end, and after a byte while /IRQ is low (FW-18: a byte may release it, only a cycle pulls it low)."""
        level = self.registers.irq_n
        if level < self._irq_level and self._irq_fell_at is None:
            self._irq_fell_at = self.now
        self._irq_level = level

    def take_interrupt(self) -> None:
        """Call the service routine for a pending falling edge of /IRQ (not nested)."""
        firmware = self.firmware
        if self._irq_fell_at is None or self._in_isr or firmware is None or not self._set_up:
            return
        latency = self.now - self._irq_fell_at
        if latency > self.irq_latency_s:
            self.irq_latency_s = latency
        self._irq_fell_at = None
        self._in_isr = True
        self.interrupts += 1
        try:
            firmware.isr(self.driver)
        finally:
            self._in_isr = False

    # -- running -----------------------------------------------------------------------------------------------

    def power_up(self) -> None:
        """Run the firmware's :meth:`Firmware.setup` (once; :meth:`run` does it if needed). Its end is the set-up's
        end: the master starts then (:class:`MasterStart`, FW-15), unless :data:`START_WAIT_S` came first. Without a
        firmware the test's own driver calls before its first run are the set-up."""
        if not self._set_up:
            self._set_up = True
            if self.firmware is not None:
                self._in_firmware = "setup"
                try:
                    self.firmware.setup(self.driver)
                finally:
                    self._in_firmware = None
            self.set_up_done(self.now)

    def set_up_done(self, at: float) -> None:
        """The firmware's set-up ended at bus time ``at`` (:class:`MasterStart`: only the first call counts): the
        master's first cycle starts at the end of that status telegram if it has not started yet, at the latest at
        :data:`START_WAIT_S` (MCU-45, FW-15). :meth:`power_up` calls it; the emulated board calls it at its core's
        first wait or first pass.

        Raises
        ------
        ArgumentError
            ``at`` not a finite number >= 0.
        """
        if self._start.set_up(at) and not self._started:
            self._next_start = self._next_at = self._start.start_s(self.config.bit_rate)

    def run(self, cycles: int) -> None:
        """Run until ``cycles`` more master cycles have finished and the firmware has served them (FW-14, as the
        emulated board's run, MCU-30), the firmware's main loop and service routine running as the clock goes.

        The master runs exactly ``cycles`` cycles, after ending one a :meth:`run_for` left under way (MCU-76,
        :attr:`under_way`); after the last one the line idles in status telegrams until the
        run ends (:class:`ServeWait`, FW-19, MCU-55), and the next run's first cycle starts at the end of the
        telegram the run ended in (or on the cycle time's schedule). Served: the interrupt of the last cycle taken
        (as the firmware would take it) and, for a firmware with a main loop, a whole pass of it (one
        :meth:`Firmware.loop` call) begun after the last cycle's end and after the last :meth:`Firmware.isr`
        (:class:`MainLoopPasses`), all within :data:`SERVE_TELEGRAMS` status telegrams of bus time from the last
        cycle's end (:func:`serve_wait_s`), checked between passes and after the service routine (the bench cannot
        cut a Python call); :attr:`served` tells whether the run ended served.

        Raises
        ------
        BenchError
            If the firmware's main loop runs :data:`IDLE_LOOPS_LIMIT` times without clocking a byte or waiting; if
            called from the firmware's own code (:meth:`_outside_firmware`), nothing runs.
        ArgumentError
            ``cycles`` not an integer from 0, or more than fit before the bus time's maximum (A26); nothing runs.
        """
        self._outside_firmware("run")
        # a cycle a run_for left under way ends first (MCU-76)
        target = self.cycles + self.under_way + check_run_cycles(cycles, self.now, self.config.bit_rate,
                                                                 self.cycle_time_s)  # fmt: skip
        self.served = False  # until the run ends served (FW-14)
        began = self.now
        self.hold_after(target)
        try:
            self._run_to(target)
            self.served = self._serve(self.last_end(began))
        finally:
            self.resume()

    @property
    def under_way(self) -> bool:
        """A master cycle has started and not ended: a :meth:`run_for`, :meth:`power_up`'s set-up or a run that raised
        ended inside it. The next run ends it first and then runs its cycles (MCU-76: as at pin level, whose
        ``run_for`` runs the cycles it starts whole, MCU-22)."""
        return bool(self.timeline) and self.timeline[-1].end > self.now

    def _outside_firmware(self, call: str) -> None:
        """Refuse ``call`` (:meth:`run`, :meth:`run_for`, :meth:`hold_after`, :meth:`resume`) from inside the
        firmware's set-up, service routine or main loop pass, which the bench itself runs: nested, the inner run's hold
        and resume broke the outer one's count of cycles (FW-19), and a main loop that ran the bench recursed without
        end."""
        inside = "isr" if self._in_isr else self._in_firmware
        if inside is not None:
            raise BenchError(f"Bench.{call}() called from the firmware's {inside}(), which the bench is running: the "
                             "test runs the bench, the firmware waits with drv.transport.delay_us() (FW-1, FW-19)")

    def hold_after(self, cycles: int) -> None:
        """MCU-55, FW-19: the master starts no cycle once :attr:`cycles` has reached ``cycles`` (a cycle under way
        ends), until :meth:`resume`: :meth:`run` and the emulated board's run hold it for their wait.

        A hold the master is stopped at (a test's ``hold_after`` and a :meth:`run_for` that reached it) is resumed
        first when ``cycles`` is above :attr:`cycles` (FW-30: the next run found the master's start at infinity and
        set the clock there).

        Raises
        ------
        ArgumentError
            ``cycles`` not an integer from 0.
        BenchError
            Called from the firmware's own code (:meth:`_outside_firmware`), as :meth:`resume`.
        """
        self._outside_firmware("hold_after")
        count = check_int("cycles", cycles, 0)
        if self._held is not None and count > self.cycles:
            self.resume()
        self._hold = count

    def last_end(self, began: float) -> float:
        """MCU-55, FW-19: the bus time the last cycle of a run begun at ``began`` ended (``began`` if none has ended
        since; :meth:`run` and the board's run count their wait from here).

        Raises
        ------
        ArgumentError
            ``began`` not a finite number >= 0, or after :attr:`now` (UP-48: a run does not begin in the future; the
            answer was that future time, from which a wait would count).
        """
        began = check_real("began", began, 0.0)
        if began > self.now:
            raise fail("began", f"a bus time up to the bench's clock, {self.now!r} s (a run begun by now)", began)
        if self._held is not None:
            return max(began, self._held[1])
        return max(began, self.timeline[-1].end) if self.timeline and self.timeline[-1].end <= self.now else began

    def resume(self) -> None:
        """MCU-55, FW-19: the run ended: the master goes on, its next cycle at the end of the status telegram the
        line idles in now, or on the cycle time's schedule if later (:func:`resume_s`).

        Raises
        ------
        BenchError
            Called from the firmware's own code (:meth:`_outside_firmware`; UP-48: a service routine's ``resume()``
            dropped the run's hold, and ``run(2)`` ran 3 cycles); nothing changes.
        """
        self._outside_firmware("resume")
        self._hold = math.inf
        held, self._held = self._held, None
        if held is not None:
            self._next_start = self._next_at = resume_s(held[1], held[0], self.now, self.config.bit_rate)

    def _run_to(self, target: float, end: float = math.inf) -> None:
        """Run until :attr:`cycles` reaches ``target``, or the clock ``end`` (:meth:`run_for`: a sleeping firmware
        sleeps to it, a main loop's pass or a service routine may end past it); then take a pending interrupt (the
        last cycle's, as the firmware would take it)."""
        self.power_up()
        loop = self._main_loop()
        idle_loops = 0
        while self.cycles < target and self.now < end:
            if self._irq_fell_at is not None:
                self.take_interrupt()
            if loop is not None:
                idle_loops = self._pass(loop, idle_loops)
            elif self.cycles >= target or self.now >= end:
                break  # the service routine ran the bus to the end
            elif (self._events[0][0] if self._events else self._next_start) > end:  # the next start or end
                self.advance(end)  # sleep to the end, the phases on the way set (the cycle goes on after it)
            else:
                self._run_bus(math.inf, True)  # sleep until the bus may change /IRQ
        self.take_interrupt()

    def _main_loop(self) -> Callable[[Supi3Driver], None] | None:
        """The firmware's :meth:`Firmware.loop` if it overrides it (a firmware without one sleeps)."""
        firmware = self.firmware
        if firmware is None or type(firmware).loop is Firmware.loop:
            return None
        return firmware.loop

    def _pass(self, loop: Callable[[Supi3Driver], None], idle_loops: int) -> int:
        """One pass of the main loop; the passes in a row before it and with it that clocked no byte and waited for
        nothing (FW-5)."""
        before = (self.now, self.bytes_clocked)
        self._in_firmware = "loop"
        try:
            loop(self.driver)
        finally:
            self._in_firmware = None
        if (self.now, self.bytes_clocked) != before:
            return 0
        if idle_loops + 1 < IDLE_LOOPS_LIMIT:
            return idle_loops + 1
        raise BenchError(f"the firmware's main loop ran {IDLE_LOOPS_LIMIT} times without clocking a byte or "
                         f"waiting, at t = {self.now:.6f} s (FW-5)")  # fmt: skip

    def _serve(self, ended: float) -> bool:
        """FW-14 (MCU-30): after the run's last cycle, which ended at ``ended``, run the main loop until a whole pass
        began after that cycle and the last service routine (:class:`MainLoopPasses`), within :func:`serve_wait_s`
        of bus time from ``ended`` (:class:`ServeWait`, FW-19); whether the run ended served. A firmware without a
        main loop is served once the last interrupt is taken, if its service routine ended within the bound."""
        wait = self._wait
        wait.begin(ended)
        try:
            loop = self._main_loop()
            if loop is None:
                return self.now <= wait.until
            return self._passes_within(loop, wait)
        finally:
            wait.end()

    def _passes_within(self, loop: Callable[[Supi3Driver], None], wait: ServeWait) -> bool:
        """:meth:`_serve`'s wait for the main loop's pass, bounded by ``wait``."""
        passes = self._passes
        passes.begin(self.now)
        end = wait.until
        interrupts = self.interrupts
        idle_loops = 0
        try:
            while True:
                if self._irq_fell_at is not None:
                    self.take_interrupt()
                if self.interrupts != interrupts:  # a service routine ran, before or within the last pass
                    interrupts = self.interrupts
                    passes.handler()
                if passes.arrive(self.now) and self.now <= end:
                    return True
                if self.now >= end:  # a pass that ends past the bound does not count (the board's core stops there)
                    return False
                idle_loops = self._pass(loop, idle_loops)
        finally:
            passes.end()
            passes.handler()

    def run_for(self, seconds: float) -> None:
        """Run until the clock has moved on by ``seconds``, the master going on (a cycle under way at the end stays
        under way, as the emulated board's ``run_for`` at transaction level; FW-19: before, the bench ran on to the
        end of a cycle); unlike :meth:`run`, the end does not wait for the main loop's pass (FW-14).

        Raises
        ------
        BenchError
            Called from the firmware's own code (:meth:`_outside_firmware`); nothing runs.
        ArgumentError
            ``seconds`` not a finite number >= 0, or past the bus time's maximum (A26); nothing runs.
        """
        self._outside_firmware("run_for")
        self._run_to(math.inf, self.now + check_run_seconds(seconds, self.now))
