"""``supi3 demo``: an INTERBUS master and a small mixed ring, live.

The ring holds three SUPI 3 chips in binary I/O modes (Tables 2-4 to 2-6) and two plain devices. The master
runs Alarm Stop and a discovery ID cycle, prints its configuration table, then runs data cycles: each SUPI 3
chip's MFP inputs go to the master, and the master's outputs appear on the chips' MFP output pins. With a VCD
path, the same scenario also runs at pin level (the SUPI 3 chips, clock by clock) and every pin is written out.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from functools import partial
from pathlib import Path

from supi3.checks import check_int
from supi3.config import DeviceConfig, decode
from supi3.errors import Supi3Error
from supi3.interbus.device import PlainDevice
from supi3.interbus.master import Master
from supi3.interbus.ring import Bus, Ring
from supi3.model.chip import Supi3
from supi3.model.pinring import PinRing
from supi3.model.pins import Supi3Pins
from supi3.model.vcd import write_vcd

SUPI3_STRAPS: tuple[tuple[str, str | None], ...] = (("10000", None), ("11011", "0011"), ("11110", None))
"""RB 8 IN/8 OUT (Table 2-6), LBD-MR 4 IN/4 OUT and LBD-OR 16 OUT (Table 2-5)."""

PLAIN_DEVICES: tuple[tuple[int, int], ...] = ((0x32, 0b00001), (0x02, 0b01001))
"""A remote bus analog input module (ID 32h, 1 word) and a digital input module (ID 02h, 1 byte), Table A-3."""


class DemoError(Supi3Error):
    """The demo could not finish: its VCD file could not be written."""


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
    try:
        write_vcd(vcd, ring)
    except OSError as exc:
        raise DemoError(f"cannot write {str(vcd)!r} (--vcd): {exc.strerror or exc}") from None
    yield f"Pin level, SUPI 3 chips only, {ring.cycle} clocks of 32 MHz:"
    yield from lines
    yield f"wrote {vcd}"
