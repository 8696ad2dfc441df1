"""The ``supi3`` command line: operating modes, pin-strap decoding, register map, timing, and the demo.

Every subcommand whose output is data takes ``--json``. Errors print one line and exit with status 2.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import NoReturn

from supi3 import tables, timing
from supi3.config import DeviceConfig, Interface, Variant, decode, mode_rows
from supi3.errors import Supi3Error


def _print_json(data: object) -> None:
    print(json.dumps(data, indent=2, ensure_ascii=False))


def _format_rows(header: Sequence[str], rows: Sequence[Sequence[object]]) -> str:
    cells = [list(map(str, header))] + [[str(c) for c in row] for row in rows]
    widths = [max(len(row[i]) for row in cells) for i in range(len(header))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)).rstrip() for row in cells]
    lines.insert(1, "  ".join("-" * w for w in widths))
    return "\n".join(lines)


def _length_text(code: str) -> str:
    return tables.LENGTH_CODE_BY_VALUE[int(code, 2)].text


def cmd_modes(args: argparse.Namespace) -> None:
    """Print the operating-mode tables (2-4 to 2-7)."""
    rows = list(mode_rows(args.variant, args.interface))
    if args.json:
        _print_json([{"table": f"Table {r.table}", "c": r.c, "mfp": r.mfp, "length_code": r.length_code,
                      "data_length": _length_text(r.length_code), "id_code": f"{r.id_code:02X}",
                      "function": r.function} for r in rows])
        return
    print(_format_rows(
        ("Table", "C[4..0]", "MFP[15..12]", "ID12..8", "Data length", "ID", "Function"),
        [(r.table, r.c, r.mfp or "-", r.length_code, _length_text(r.length_code), f"{r.id_code:02X}h", r.function)
         for r in rows],
    ))


def describe(config: DeviceConfig) -> str:
    """A human-readable description of a decoded configuration."""
    d = config.as_dict()
    lines = [f"{key:20} {value}" for key, value in d.items()]
    pins = ", ".join(f"MFP{p.pin}={p.signal}({p.direction.value})" for p in config.mfp_pins)
    lines.append(f"{'mfp_pins':20} {pins or '-'}")
    return "\n".join(lines)


def cmd_decode(args: argparse.Namespace) -> None:
    """Decode pin straps into a configuration."""
    config = decode(args.c, args.mfp, args.rf, args.clk_conf, args.diag_conf, args.variant)
    if args.json:
        data = config.as_dict()
        data["mfp_pins"] = [{"pin": p.pin, "signal": p.signal, "direction": p.direction.value}
                            for p in config.mfp_pins]
        _print_json(data)
    else:
        print(describe(config))


def cmd_regmap(args: argparse.Namespace) -> None:
    """Render the register map."""
    from supi3.regmap import render

    out = Path(args.output) if args.output else None
    text = render(args.format, out)
    if out is None:
        sys.stdout.write(text)
    else:
        print(f"wrote {out}")


def cmd_timing(args: argparse.Namespace) -> None:
    """Data cycle time, CPU access time, I/O access window, optical length; optionally a timing table."""
    bit_rate = _parse_bit_rate(args.bit_rate)
    data = timing.report(args.bytes, bit_rate, args.devices)
    if args.optical_count is not None:
        length = timing.optical_length_m(args.optical_count, bit_rate)
        data["optical_count"] = args.optical_count
        data["optical_length_m"] = length
    if args.table:
        data["table"] = [
            {"symbol": r.symbol, "explanation": r.explanation,
             "min_ns": None if r.minimum_s is None else round(r.minimum_s * 1e9, 3),
             "max_ns": None if r.maximum_s is None else round(r.maximum_s * 1e9, 3)}
            for r in timing.timing_table(args.table, bit_rate, args.bytes)
        ]
    if args.json:
        _print_json(data)
        return
    for key, value in data.items():
        if key != "table":
            print(f"{key:26} {value}")
    if args.table:
        print(f"\nTable {args.table} at {bit_rate} bit/s:")
        table = data["table"]
        assert isinstance(table, list)
        print(_format_rows(("Symbol", "Min (ns)", "Max (ns)", "Explanation"),
                           [(r["symbol"], r["min_ns"] if r["min_ns"] is not None else "-",
                             r["max_ns"] if r["max_ns"] is not None else "-", r["explanation"]) for r in table]))


def _parse_bit_rate(text: str) -> int:
    aliases = {"500k": 500_000, "500000": 500_000, "2m": 2_000_000, "2000000": 2_000_000}
    try:
        return aliases[text.lower()]
    except KeyError:
        raise timing.TimingError(f"bit rate {text!r}: choose 500k or 2M (Table 1-7)") from None


def regmap_summary() -> str:
    """One line per address of the register map: what a write and a read reach, and how."""
    from supi3.regmap import REGISTER_MAP, Direction

    rows = []
    for address in REGISTER_MAP.addresses:
        cells: list[object] = [address]
        for direction in (Direction.WRITE, Direction.READ):
            port = REGISTER_MAP.port(address, direction)
            name = port.register.name if port.register else ""
            cells += [f"{port.title} ({name})" if name else port.title, port.access.value]
        rows.append(cells)
    return _format_rows(("Addr", "Write", "Access", "Read", "Access"), rows)


def cmd_demo(args: argparse.Namespace) -> None:
    """A master and a small ring, live; optionally the pin-level run as a VCD."""
    from supi3 import demo

    clk_conf = {500_000: "01", 2_000_000: "11"}[_parse_bit_rate(args.bit_rate)]
    if args.cycles < 1:
        raise timing.TimingError(f"--cycles must be at least 1, not {args.cycles}")
    for line in demo.run(args.cycles, Path(args.vcd) if args.vcd else None, clk_conf):
        print(line)
    print("\nRegister map of the serial µP interface (Table 3-10; `supi3 regmap` for all formats):\n")
    print(regmap_summary())


def cmd_campaign(args: argparse.Namespace) -> None:
    """A seeded fault campaign at transaction and/or pin level (supi3.campaign); exit status 1 if a goal is missed."""
    from supi3 import campaign

    results = [campaign.run_campaign(config) for config in campaign.configs_from_args(args)]
    print(campaign.report(results, args.json))
    if not all(r.ok for r in results):
        raise SystemExit(1)


class _Parser(argparse.ArgumentParser):
    """An argument parser whose usage errors are one line, like every other supi3 error."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``supi3`` command."""
    parser = _Parser(prog="supi3", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("demo", help="a master and a small ring, live (built-in defaults)")
    p.add_argument("--cycles", type=int, default=4, help="data cycles to run (default 4)")
    p.add_argument("--vcd", metavar="PATH", help="also run the SUPI 3 chips at pin level and write a VCD")
    p.add_argument("--bit-rate", default="500k", help="500k or 2M")
    p.set_defaults(func=cmd_demo)

    p = sub.add_parser("modes", help="list the operating modes (Tables 2-4 to 2-7)")
    p.add_argument("--variant", choices=[v.value for v in Variant], default="opc")
    p.add_argument("--interface", choices=[i.value for i in Interface])
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_modes)

    p = sub.add_parser("decode", help="decode pin straps into a device configuration")
    p.add_argument("--c", required=True, metavar="BITS", help="C[4..0], e.g. 10011")
    p.add_argument("--mfp", metavar="BITS", help="MFP[15..12], for modes with configuration expansion")
    p.add_argument("--rf", metavar="BITS", help="RF[1..0] (OPC only; open = 11)")
    p.add_argument("--clk-conf", metavar="BITS", default="01", help="CLK_CONF[1..0] (default 01: 500 kbit/s)")
    p.add_argument("--diag-conf", metavar="BIT", help="DIAG_CONF (OPC only; open = 1)")
    p.add_argument("--variant", default="opc", help="opc or ls")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_decode)

    p = sub.add_parser("regmap", help="render the register map")
    p.add_argument("--format", required=True, choices=["html", "md", "rdl", "h", "json"])
    p.add_argument("-o", "--output", metavar="PATH", help="write to PATH (a directory for html)")
    p.set_defaults(func=cmd_regmap)

    p = sub.add_parser("timing", help="CPU access time, I/O access window, cycle time, optical length")
    p.add_argument("--bit-rate", default="500k", help="500k or 2M")
    p.add_argument("--bytes", type=int, default=4, help="data bytes in the whole network (default 4)")
    p.add_argument("--devices", type=int, default=1, help="devices in the ring (default 1)")
    p.add_argument("--optical-count", type=int, metavar="N", help="length timer result n (1.6.1)")
    p.add_argument("--table", choices=sorted(timing.TIMING_TABLES), help="also evaluate a timing table")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_timing)

    p = sub.add_parser("campaign", help="a seeded fault campaign: error locations, latches, recovery, memory")
    from supi3.campaign import add_arguments

    add_arguments(p)
    p.set_defaults(func=cmd_campaign)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``supi3`` command."""
    args = build_parser().parse_args(argv)
    try:
        args.func(args)
    except Supi3Error as exc:
        print(f"supi3: error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
