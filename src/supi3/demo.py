"""``supi3 demo``: an INTERBUS master and a small mixed ring, live.

The ring holds three SUPI 3 chips in binary I/O modes (Tables 2-4 to 2-6) and two plain devices. The master
runs Alarm Stop and a discovery ID cycle, prints its configuration table, then runs data cycles: each SUPI 3
chip's MFP inputs go to the master, and the master's outputs appear on the chips' MFP output pins. With a VCD
path, the same scenario also runs at pin level (the SUPI 3 chips, clock by clock) and every pin is written out.

``supi3 demo --analog`` (:func:`run_analog`): an analog I/O device built on the SPI master mode (manual 3.3): a
SUPI 3 OPC strapped for RB, SPI 16 IN/16 OUT (Table 2-6) with a 16-bit SPI DAC and a 16-bit SPI ADC on its serial
I/O bus, the DAC's output wired back to the ADC's input. The master writes a setpoint ramp; it appears at the DAC
output and, through the ADC, comes back to the master. With a VCD path the same scenario runs at pin level too, and
the analog chip's SPI pins are checked against Table 3-4.

``supi3 demo --optical`` (:func:`run_optical`): a ring of SUPI 3 OPC chips joined by polymer, HCS and glass fibre
(manual 1.6): optical initialization, the master's optical diagnostic table (Figure 1-10), a bent fibre that online
regulation compensates, a pulled connector the master locates, and a plot of the disturbed path's power levels.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from functools import partial
from html import escape
from pathlib import Path

from supi3 import serial_io
from supi3.checks import check_instance, check_int
from supi3.config import DeviceConfig, decode
from supi3.errors import Supi3Error
from supi3.interbus import wire
from supi3.interbus.device import PlainDevice
from supi3.interbus.master import Diagnostic, Master
from supi3.interbus.ring import Branch, BranchKind, Bus, Ring
from supi3.model.chip import Supi3
from supi3.model.pinring import PinRing
from supi3.model.pins import Supi3Pins
from supi3.model.vcd import write_vcd
from supi3.optical.link import Bend, Fibre, FibreLink, Pull
from supi3.optical.regulation import MAX_LEVEL
from supi3.optical.ring import OpticalRing, PathSample, diagnostic_table, format_table
from supi3.peripherals.serial import SerialBus, SpiAdc, SpiDac
from supi3.tables import CLOCK_HZ, MODE_ROWS
from supi3.verif.timing import check_serial_io

SUPI3_STRAPS: tuple[tuple[str, str | None], ...] = (("10000", None), ("11011", "0011"), ("11110", None))
"""RB 8 IN/8 OUT (Table 2-6), LBD-MR 4 IN/4 OUT and LBD-OR 16 OUT (Table 2-5)."""

PLAIN_DEVICES: tuple[tuple[int, int], ...] = ((0x32, 0b00001), (0x02, 0b01001))
"""A remote bus analog input module (ID 32h, 1 word) and a digital input module (ID 02h, 1 byte), Table A-3."""


ANALOG_STRAPS: tuple[tuple[str, str | None], ...] = (("10011", "1000"), ("10000", None))
"""The SUPI 3 chips of ``--analog``: the analog device, RB SPI 16 IN/16 OUT (Table 2-6, ID 33h: one 16-bit word
each way, one 16-bit ADC and DAC on one /SS frame each, SM-3), then an RB 8 IN/8 OUT binary I/O chip (Table 2-6)."""

ANALOG_PLAIN_DEVICES: tuple[tuple[int, int], ...] = ((0x02, 0b01001),)
"""``--analog``: a digital input module (ID 02h, 1 byte, Table A-3) behind the SUPI 3 chips (transaction level)."""

VREF = 5.0
"""Reference voltage of the ``--analog`` demo's DAC and ADC, in volts."""

RAMP_STEP = 0x2000
"""The ``--analog`` setpoint ramp: one step a cycle, 0.625 V at :data:`VREF`; the 16-bit word wraps every 8th cycle."""


class DemoError(Supi3Error):
    """The demo could not finish: its VCD file (or the ``--optical`` plot) could not be written."""


def _configs(clk_conf: str) -> list[DeviceConfig]:
    return [decode(c, mfp, clk_conf=clk_conf) for c, mfp in SUPI3_STRAPS]


def _pattern(cycle: int, k: int) -> int:
    return (0x1111 * (cycle + 1) + 0x0F0F * k) & 0xFFFF


def _table(master: Master) -> Iterator[str]:
    assert master.config is not None
    yield f"{'Pos':>3}  {'Device':>6}  {'ID':>3}  {'Length':>9}  {'Interface':12}  Table A-3"
    for e in master.config:
        row = e.id_row.description if e.id_row else "(not in Table A-3)"
        yield (f"{e.ring_position:>3}  {e.number:>6}  {e.id_code:02X}h  {e.data_bits:>5} bit  "
               f"{e.interface.value:12}  {row}")


def _drive(master: Master, chips: list[Supi3], cycles: int, set_mfp: Sequence[Callable[[int], None]],
           after: Callable[[], None] = lambda: None) -> Iterator[str]:
    """Run data cycles (``after`` each one); yield one line per cycle."""
    assert master.config is not None
    for n in range(cycles):
        parts = []
        for k, entry in enumerate(master.config, start=1):
            out = (_pattern(n, k) & ((1 << 8 * entry.data_bytes) - 1)).to_bytes(entry.data_bytes, "big")
            master.set_outputs(k, out)
        for k, setter in enumerate(set_mfp):
            setter(_pattern(n, k + 7))
        result = master.data_cycle()
        after()
        for k, chip in enumerate(chips, start=1):
            parts.append(f"{k}: OUT {master.outputs(k).hex()} -> MFP {chip.mfp_outputs:04X}, "
                         f"IN {master.inputs(k).hex()}")
        status = "ok" if result.ok else "FAILED"
        yield f"  cycle {n + 1} ({status}, {master.ring.now * 1e3:7.3f} ms)  " + "  |  ".join(parts)


def run(cycles: int = 4, vcd: Path | None = None, clk_conf: str = "01") -> Iterator[str]:
    """The demo, as lines of text.

    Raises
    ------
    ArgumentError
        If ``cycles`` is not an integer >= 1.
    DemoError
        If the VCD file cannot be written (the command line checks the path before the run).
    """
    check_int("cycles", cycles, 1)
    configs = _configs(clk_conf)
    chips = [Supi3(c) for c in configs]
    devices: list[Supi3 | PlainDevice] = [*chips, *(PlainDevice(id_code, length) for id_code, length in PLAIN_DEVICES)]
    ring = Ring(devices, bit_rate=configs[0].bit_rate)
    master = Master(ring)
    result = master.start()
    yield (f"supi3 demo: INTERBUS master and a ring of {len(devices)} devices at {ring.bit_rate // 1000} kbit/s "
           f"(transaction level)")
    yield f"Alarm Stop (1303h) and discovery ID cycle: {'ok' if result.ok else 'FAILED'}"
    yield "Configuration table:"
    yield from (f"  {line}" for line in _table(master))
    yield "Data cycles (master OUT -> chip MFP outputs; chip MFP inputs -> master IN), SUPI 3 chips 1-3:"
    yield from _drive(master, chips, cycles, [chip.set_mfp_inputs for chip in chips])
    if vcd is not None:
        yield from _pin_level(configs, cycles, vcd)


def _write(vcd: Path, ring: PinRing) -> None:
    try:
        write_vcd(vcd, ring)
    except OSError as exc:
        raise DemoError(f"cannot write {str(vcd)!r} (--vcd): {exc.strerror or exc}") from None


def _pin_level(configs: list[DeviceConfig], cycles: int, vcd: Path) -> Iterator[str]:
    pins = [Supi3Pins(c) for c in configs]
    ring = PinRing(pins, record=True)
    ring.settle()  # power-up reset stretch
    bus: Bus = ring
    master = Master(bus, locate=False, max_devices=len(pins))
    master.start()
    setters = [partial(ring.set_input, k, "mfp_in") for k in range(1, len(pins) + 1)]
    # The latch telegrams reach the chips further down the ring a few bit periods after the master sent them.
    lines = list(_drive(master, [p.chip for p in pins], cycles, setters, ring.settle))
    _write(vcd, ring)
    yield f"Pin level, SUPI 3 chips only, {ring.cycle} clocks of 32 MHz:"
    yield from lines
    yield f"wrote {vcd}"


# ------------------------------------------------------------------------------------------------------------
# --analog: an ADC and a DAC behind a SUPI 3 in the SPI master mode (3.3)
# ------------------------------------------------------------------------------------------------------------


def setpoint(cycle: int) -> int:
    """The master's OUT word in data cycle ``cycle`` (0 first) of ``--analog``: a ramp of :data:`RAMP_STEP`."""
    return (RAMP_STEP * (cycle + 1)) & 0xFFFF


def _analog(master: Master, adc: SpiAdc, dac: SpiDac, cycles: int, after: Callable[[], None]) -> Iterator[str]:
    """Run data cycles (``after`` each one) on the analog device at ring position 1; yield one line per cycle.

    The analog path is a wire from the DAC's output to the ADC's input: the ADC samples, at the read frame of a
    cycle's sequence, what the DAC put out since the sequence before (the write frame comes after the read frame,
    3.3.1), and the master gets that sample in the next data cycle.
    """
    level = dac.volts(VREF)
    for n in range(cycles):
        master.set_outputs(1, setpoint(n).to_bytes(2, "big"))
        adc.set_voltage(level, VREF)
        result = master.data_cycle()
        after()
        status = "ok" if result.ok else "FAILED"
        yield (f"  cycle {n + 1} ({status}, {master.ring.now * 1e3:7.3f} ms)  "
               f"master OUT {master.outputs(1).hex().upper()}h -> DAC {dac.output:04X}h = {dac.volts(VREF):.3f} V  "
               f"|  ADC input {level:.3f} V = {adc.code:04X}h  |  master IN {master.inputs(1).hex().upper()}h")
        level = dac.volts(VREF)


def _converters(config: DeviceConfig) -> tuple[SpiAdc, SpiDac, SerialBus]:
    width = config.mfp_mode.width
    adc, dac = SpiAdc(width), SpiDac(width)
    return adc, dac, SerialBus(adc, dac)


def run_analog(cycles: int = 4, vcd: Path | None = None, clk_conf: str = "01") -> Iterator[str]:
    """The ``--analog`` demo, as lines of text: a SUPI 3 in the SPI master mode with an SPI ADC and DAC (3.3).

    The master writes the ramp :func:`setpoint` to the analog chip's OUT word; the chip's sequence after each valid
    data cycle (read frame, write frame, /Conv, SM-6) shifts it into the DAC, whose output is wired to the ADC's
    input; the ADC's sample travels to the master in the next data cycle. One line per cycle shows the master's OUT
    word, the DAC's code and output voltage, the ADC's input and code, and the master's IN word. With ``vcd``, the
    SUPI 3 chips run the same scenario at pin level, every pin is written out, and the analog chip's MFP pins are
    checked against Table 3-4 (:func:`supi3.verif.timing.check_serial_io`).

    Raises
    ------
    ArgumentError
        If ``cycles`` is not an integer >= 1.
    DemoError
        If the VCD file cannot be written (the command line checks the path before the run).
    """
    check_int("cycles", cycles, 1)
    configs = [decode(c, mfp, clk_conf=clk_conf) for c, mfp in ANALOG_STRAPS]
    chips = [Supi3(c) for c in configs]
    adc, dac, bus = _converters(configs[0])
    chips[0].attach_serial(bus)
    devices: list[Supi3 | PlainDevice] = [*chips, *(PlainDevice(i, length) for i, length in ANALOG_PLAIN_DEVICES)]
    ring = Ring(devices, bit_rate=configs[0].bit_rate)
    master = Master(ring)
    result = master.start()
    yield (f"supi3 demo --analog: INTERBUS master and a ring of {len(devices)} devices at "
           f"{ring.bit_rate // 1000} kbit/s (transaction level)")
    yield (f"Device 1: {configs[0].interface.value}, {configs[0].mfp_mode.name} (Table 2-6) with a "
           f"{adc.bits}-bit SPI ADC and a {dac.bits}-bit SPI DAC (vref {VREF:g} V) on its serial I/O bus (3.3); "
           f"the DAC output is wired to the ADC input")
    yield f"Alarm Stop (1303h) and discovery ID cycle: {'ok' if result.ok else 'FAILED'}"
    yield "Configuration table:"
    yield from (f"  {line}" for line in _table(master))
    yield ("Data cycles (master OUT -> DAC; DAC output -> ADC input, sampled before the DAC takes the new word "
           "-> master IN one cycle later), device 1:")
    yield from _analog(master, adc, dac, cycles, lambda: None)
    if vcd is not None:
        yield from _analog_pin_level(configs, cycles, vcd)


def _analog_pin_level(configs: list[DeviceConfig], cycles: int, vcd: Path) -> Iterator[str]:
    pins = [Supi3Pins(c) for c in configs]
    adc, dac, bus = _converters(configs[0])
    pins[0].chip.attach_serial(bus)
    ring = PinRing(pins, record=True)
    ring.settle()  # power-up reset stretch
    master = Master(ring, locate=False, max_devices=len(pins))
    master.start()
    mode = configs[0].mfp_mode
    sequence = serial_io.sequence(mode.direction, mode.width, ring.bit_rate)

    def after() -> None:
        # The latch telegrams reach every chip, then the sequence runs to its end, so the word read travels in
        # the next data cycle (SM-6; the transaction level runs the sequence at the latch).
        ring.settle()
        ring.idle(sequence.length / CLOCK_HZ)

    lines = list(_analog(master, adc, dac, cycles, after))
    violations = check_serial_io(ring.recorded()[0], bit_rate=ring.bit_rate, bits=mode.width)
    _write(vcd, ring)
    yield f"Pin level, SUPI 3 chips only, {ring.cycle} clocks of 32 MHz:"
    yield from lines
    count = f"{len(violations) or 'no'} violation{'' if len(violations) == 1 else 's'}"
    yield f"Table 3-4 on device 1's SPI pins (MFP3..MFP7): {count}"
    yield from (f"  {violation}" for violation in violations)
    yield f"wrote {vcd}"


# ------------------------------------------------------------------------------------------------------------
# --optical: a ring of SUPI 3 OPC chips joined by fibre cables (manual 1.6), a bend and a pulled connector
# ------------------------------------------------------------------------------------------------------------

OPTICAL_CABLES: tuple[tuple[float, Fibre], ...] = (
    (15.0, Fibre.POLYMER), (45.0, Fibre.POLYMER), (300.0, Fibre.HCS), (65.0, Fibre.POLYMER), (35.0, Fibre.POLYMER),
    (25.0, Fibre.POLYMER), (1500.0, Fibre.GLASS), (30.0, Fibre.POLYMER),
)  # fmt: skip
"""``--optical``: the cable into each device (one-way metres, fibre), in ring order: 1.0 from the master, 2.0, the
bus terminal module 3.0, its local bus devices 3.1 (from the BK's branch interface) to 3.3, then 4.0 (from the BK's
outgoing interface) and 5.0."""

BUS_TERMINAL_LBD: str = next(row.c for row in MODE_ROWS if row.function.startswith("BK-LBD"))
"""C[4..0] of the bus terminal module with a local bus with device-oriented diagnostics (Table 2-7)."""

LBD_MR: str = next(row.c for row in MODE_ROWS if row.function == "LBD-MR, 8 IN/8 OUT")
"""C[4..0] of a local bus device with device-oriented diagnostics and return line, 8 IN / 8 OUT (Table 2-5)."""

OPTICAL_BK: int = 3
"""``--optical``: the ring position of the bus terminal module (BK-LBD, Table 2-7)."""

OPTICAL_BRANCH: int = 3
"""``--optical``: the LBD-MR devices of its local bus (device-oriented diagnostics, 2.2.2)."""

OPTICAL_BENT: int = 4
"""``--optical``: the cable that is bent, into ring position 4 (the branch path 3.0<->3.1)."""

OPTICAL_PULLED: int = 6
"""``--optical``: the cable whose connector is pulled, into ring position 6 (the local bus path 3.2<->3.3)."""

OPTICAL_BEND: tuple[int, int, float] = (60, 120, 4.0)
"""``--optical``: the bend, from data-cycle time 60 for 120 cycle times, 4 dB on both fibres."""

OPTICAL_PULL: tuple[int, int] = (260, 70)
"""``--optical``: the connector pulled at cycle time 260 and put back after 70 cycle times (longer than the 20 ms
silent-line timeout at 500 kbit/s, so the chips behind it reset)."""

OPTICAL_CYCLES = 480
"""``--optical``: data cycles to run by default."""


def _optical_path(ring: OpticalRing, k: int, master: Master) -> str:
    ends = ring.ends(k)
    assert ends is not None
    up = "master" if ends[0] == 0 else master.entry(ends[0]).number
    return f"{up}<->{master.entry(ends[1]).number}"


def _message(d: Diagnostic) -> str:
    """One of the master's messages as the demo prints it."""
    if d.mau is not None:
        name, on = d.mau
        where = {"MAUWH": "incoming", "MAUWR": "outgoing", "MAUWS": "branch"}[name]
        return f"MAU warning {'on ' if on else 'off'} at {d.device} {where} interface ({name}, {d.code:04X}h)"
    if d.location is None:
        return f"cycle failed: {d.kind.value} not located"
    text = f"cycle failed: {d.kind.value} at {d.device} (line {d.location})"
    lbd = d.detail.partition("device-oriented local-bus diagnostics: ")[2]
    return f"{text}, by the counter telegram: {lbd}" if lbd else text


def run_optical(cycles: int = OPTICAL_CYCLES, plot: Path | None = None, clk_conf: str = "01") -> Iterator[str]:
    """The ``--optical`` demo, as lines of text: a ring of SUPI 3 OPC chips in optical regulation mode (RF = 00, 1.6)
    joined by polymer, HCS and glass cables (:mod:`supi3.optical.link`), with a bus terminal module (BK-LBD) whose
    local bus of three LBD-MR devices hangs on its branch interface (2.4, Figure 1-10). After Alarm Stop every cable
    initializes (1.6.1) and the master prints its optical diagnostic table (Figure 1-10); during the data cycles the
    branch path 3.0<->3.1 is bent (online regulation raises the power, the MAU warnings come and go and the master
    reports them, 1.6.2, 1.6.3) and the connector of the local bus path 3.2<->3.3 is pulled (the master locates the
    break on its exact line by the counter telegram, 2.2.2; after the repair it restarts the bus). With ``plot``, a
    self-contained HTML page with an SVG plot of the bent path's power levels over time.

    Raises
    ------
    ArgumentError
        If ``cycles`` is not an integer >= 1 or ``plot`` not a :class:`~pathlib.Path` (checked before the run).
    DemoError
        If the plot cannot be written (the command line checks the path before the run).
    """
    check_int("cycles", cycles, 1)
    if plot is not None:
        check_instance("plot", plot, Path, "a pathlib.Path or None")  # before the run, not after it

    def chip(straps: str) -> Supi3:
        return Supi3(decode(straps, rf="00", clk_conf=clk_conf))

    branch = Branch(chip(BUS_TERMINAL_LBD), [chip(LBD_MR) for _ in range(OPTICAL_BRANCH)], BranchKind.LBD_MR)
    devices = [chip("10000") for _ in range(OPTICAL_BK - 1)] + [branch]
    devices += [chip("10000") for _ in range(len(OPTICAL_CABLES) - OPTICAL_BK - OPTICAL_BRANCH)]
    cables = [FibreLink(metres, fibre) for metres, fibre in OPTICAL_CABLES]
    ring = OpticalRing(devices, cables)
    master = Master(ring)
    result = master.start()
    yield (f"supi3 demo --optical: INTERBUS master and a ring of {len(ring.chips)} SUPI 3 OPC chips joined by fibre "
           f"(RF = 00, optical regulation), a bus terminal module ({OPTICAL_BK}.0, BK-LBD) with a local bus of "
           f"{OPTICAL_BRANCH} LBD-MR devices, {ring.bit_rate // 1000} kbit/s (transaction level)")
    yield "Cables: " + "; ".join(f"{_optical_path(ring, k, master)} {c.length_m:g} m {c.fibre.value}"
                                 for k, c in enumerate(cables, 1))  # fmt: skip
    yield (f"Alarm Stop (1303h), optical initialization (the cores held until {ring.history[0][0].time_s * 1e3:.3f} "
           f"ms) and discovery ID cycle: {'ok' if result.ok else 'FAILED'}")
    yield "Optical diagnostic table (Figure 1-10):"
    yield from (f"  {line}" for line in format_table(diagnostic_table(ring, master)))
    tick = wire.cycle_bits(len(ring.chips), len(ring.chips)) / ring.bit_rate
    t0 = ring.now
    bent, pulled = _optical_path(ring, OPTICAL_BENT, master), _optical_path(ring, OPTICAL_PULLED, master)
    bend = Bend(t0 + OPTICAL_BEND[0] * tick, OPTICAL_BEND[1] * tick, OPTICAL_BEND[2])
    pull = Pull(t0 + OPTICAL_PULL[0] * tick, OPTICAL_PULL[1] * tick)
    cables[OPTICAL_BENT - 1].add(bend)
    cables[OPTICAL_PULLED - 1].add(pull)
    yield (f"{cycles} data cycles; path {bent} bent by {bend.loss_db:g} dB from {bend.start_s * 1e3:.3f} ms to "
           f"{(bend.start_s + (bend.duration_s or 0)) * 1e3:.3f} ms, the connector of path {pulled} pulled from "
           f"{pull.start_s * 1e3:.3f} ms to {(pull.start_s + (pull.duration_s or 0)) * 1e3:.3f} ms; "
           "the master's messages:")
    yield from _optical_run(ring, master, cycles)
    yield f"Optical diagnostic table at {ring.now * 1e3:.3f} ms:"
    yield from (f"  {line}" for line in format_table(diagnostic_table(ring, master)))
    if plot is not None:
        _write_plot(plot, _plot_html(ring.history[OPTICAL_BENT - 1], bent, (bend, pull), pulled))
        yield f"wrote {plot}"


def _optical_run(ring: OpticalRing, master: Master, cycles: int) -> Iterator[str]:
    """Run ``cycles`` data cycles; yield the master's messages (a failure once per diagnosis) and restarts."""
    last = ""
    failed = False
    for n in range(cycles):
        for k, entry in enumerate(master.config or (), 1):
            master.set_outputs(k, bytes([(n + k) & 0xFF]) * entry.data_bytes)
        result = master.cycle()
        failed = failed or not result.ok
        for d in result.diagnostics:
            text = _message(d)
            if text != last or d.mau is not None:
                yield f"  {ring.now * 1e3:8.3f} ms  {text}"
            last = text
        if result.ok and failed and not any(ring.dark(k) for k in range(1, len(ring.links) + 1)):
            failed, last = False, ""
            back = ring.now
            restarted = master.start()
            yield (f"  {back * 1e3:8.3f} ms  the ring runs again: Alarm Stop, optical initialization and discovery "
                   f"ID cycle: {'ok' if restarted.ok else 'FAILED'} at {ring.now * 1e3:.3f} ms")


def _write_plot(path: Path, html: str) -> None:
    try:
        path.write_text(html, encoding="utf-8")
    except OSError as exc:
        raise DemoError(f"cannot write {str(path)!r} (--plot): {exc.strerror or exc}") from None


_PLOT_W, _PLOT_H, _PLOT_M = 760, 300, 48
"""The plot's width and height in pixels and its margin for the axes."""


def _plot_html(samples: Sequence[PathSample], path: str, events: tuple[Bend, Pull], pulled: str) -> str:
    """A self-contained HTML page with an inline SVG: the power levels of a path's two transmitters over bus time
    (step lines), the bend and the pulled connector (of path ``pulled``) as shaded bands."""
    t0, t1 = samples[0].time_s, samples[-1].time_s
    span = max(t1 - t0, 1e-9)
    path, pulled = escape(path), escape(pulled)

    def x(t: float) -> float:
        return _PLOT_M + (min(max(t, t0), t1) - t0) / span * (_PLOT_W - 2 * _PLOT_M)

    def y(level: float) -> float:
        return _PLOT_H - _PLOT_M - level / MAX_LEVEL * (_PLOT_H - 2 * _PLOT_M)

    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{_PLOT_W}" height="{_PLOT_H}" '
             f'viewBox="0 0 {_PLOT_W} {_PLOT_H}" font-family="sans-serif" font-size="11">']
    for event, colour, label in ((events[0], "#fde2a8", "bend"), (events[1], "#f4b4b4", f"{pulled} pulled")):
        end = event.start_s + (event.duration_s or span)
        parts.append(f'<rect x="{x(event.start_s):.1f}" y="{_PLOT_M}" width="{x(end) - x(event.start_s):.1f}" '
                     f'height="{_PLOT_H - 2 * _PLOT_M}" fill="{colour}"><title>{label}</title></rect>')
        parts.append(f'<text x="{x(event.start_s) + 3:.1f}" y="{_PLOT_M + 12}">{label}</text>')
    for tick_level in range(0, MAX_LEVEL + 1, 5):
        at = y(tick_level)
        parts.append(f'<line x1="{_PLOT_M}" x2="{_PLOT_W - _PLOT_M}" y1="{at:.1f}" y2="{at:.1f}" stroke="#ddd"/>'
                     f'<text x="{_PLOT_M - 6}" y="{at + 4:.1f}" text-anchor="end">{tick_level}</text>')
    for i in range(5):
        t = t0 + span * i / 4
        parts.append(f'<text x="{x(t):.1f}" y="{_PLOT_H - _PLOT_M + 16}" text-anchor="middle">{t * 1e3:.1f}</text>')
    parts.append(f'<text x="{_PLOT_W / 2}" y="{_PLOT_H - 8}" text-anchor="middle">bus time (ms)</text>')
    parts.append(f'<text x="14" y="{_PLOT_H / 2}" transform="rotate(-90 14 {_PLOT_H / 2})" '
                 f'text-anchor="middle">power level (of {MAX_LEVEL})</text>')
    for attr, colour, name in (("forward_level", "#1f5fbf", "forward"), ("return_level", "#d0701a", "return")):
        points = []
        previous: int | None = None
        for s in samples:
            level: int = getattr(s, attr)
            if previous is not None:
                points.append(f"{x(s.time_s):.1f},{y(previous):.1f}")
            points.append(f"{x(s.time_s):.1f},{y(level):.1f}")
            previous = level
        parts.append(f'<polyline fill="none" stroke="{colour}" stroke-width="2" points="{" ".join(points)}">'
                     f"<title>{name}</title></polyline>")
    parts.append(f'<text x="{_PLOT_W - _PLOT_M}" y="{_PLOT_M - 22}" text-anchor="end"><tspan fill="#1f5fbf">'
                 f'forward</tspan> / <tspan fill="#d0701a">return</tspan> transmitter</text>')
    parts.append("</svg>")
    title = f"supi3 demo --optical: power levels of path {path}"
    return (f'<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8"><title>{title}</title></head>\n<body>'
            f"<h1>{title}</h1>\n<p>Online regulation (manual 1.6.2): each transmitter's power level over bus time; "
            f"the bend raises it, the pulled connector of path {pulled} interrupts the ring until the master "
            "restarts it.</p>\n"
            + "".join(parts) + "\n</body></html>\n")
