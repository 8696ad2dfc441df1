"""The ``supi3`` command line: operating modes, pin-strap decoding, register map, timing, the demo, figures, the C SDK.

Every subcommand whose output is data takes ``--json``.

Exit status and what goes to stderr, for every subcommand. :func:`main` does it all, so a new subcommand gets it
by raising a :class:`~supi3.errors.Supi3Error` for bad input, taking integer options with ``type=integer`` (and
their limits with :func:`~supi3.checks.check_int`), and checking its output paths with :func:`output_file` or
:func:`output_dir` before it starts working. ``SystemExit(n)`` from a subcommand becomes its status ``n``.

- 0: done.
- 2: bad input, one line on stderr and never a traceback: a usage error (unknown option or choice, a value that is
  not a plain decimal integer, an abbreviated option), a value the manual rules out (any ``Supi3Error``), an output
  path that cannot be written (empty, a directory, a missing folder, a name too long; checked before any work), a
  write that fails (``-o /dev/full``, ``> /dev/full``), ``regmap --format html`` or ``figures`` without the ``docs``
  extra.
- 141 (128 + SIGPIPE): the reader closed the pipe early (``supi3 demo | head``). Nothing on stderr, like a Unix
  tool killed by SIGPIPE; under ``set -o pipefail`` the pipeline fails, as it does for ``seq``.
- 130: interrupted (Ctrl-C), nothing on stderr.
- 3 and 4, ``firmware run`` only: the firmware faulted, ran away or used up its budget (3), or broke an interface
  rule or did not exchange the process data (4); the report is on stdout.
- 1 with a traceback: a genuine bug (any other exception). It is kept so that it can be reported.

Options are spelt out in full (an abbreviation is an error, so a new option can never change what an old command
line means); a repeated option takes its last value. Output folders are not created. A character stdout cannot
encode gets a stand-in (``µ`` becomes ``u`` on an ASCII terminal); JSON stays lossless with ``\\u`` escapes.
"""

from __future__ import annotations

import argparse
import codecs
import contextlib
import json
import os
import re
import shlex
import sys
import unicodedata
from collections.abc import Sequence
from pathlib import Path
from typing import Any, NoReturn, TextIO

from supi3 import campaign, serial_io, tables, timing
from supi3.checks import check_int, check_real, fail
from supi3.checks import describe as _shown
from supi3.config import DeviceConfig, Interface, MfpKind, Variant, decode, mode_rows
from supi3.errors import ArgumentError, Supi3Error
from supi3.optical import length as optical_length
from supi3.regmap import LENGTH_OUT
from supi3.sdk.bench import DEFAULT_STRAPS

MAX_NETWORK_BYTES = timing.MAX_NETWORK_BYTES
"""``timing --bytes`` limit: 512 devices (the INTERBUS limit) of the longest data length, 32 words (Table 3-11)."""

MAX_OPTICAL_COUNT = timing.MAX_OPTICAL_COUNT
"""``timing --optical-count`` limit: the length timer's result for a 20 km path at 2 Mbit/s, 6,400 (1,600 at 500
kbit/s; Table 1-5, OPT-1)."""

DEMO_CYCLES = 4
"""``demo --cycles`` default (``--optical`` runs its whole scenario by default)."""

MAX_DEMO_CYCLES = 1000
"""``demo --cycles`` limit: a demo, not a soak test."""

MAX_VCD_CYCLES = 50
"""``demo --cycles`` limit with ``--vcd``: the pin-level run keeps every pin of every 32 MHz clock until it writes
the VCD, about 10 MB of memory a data cycle at 500 kbit/s (1000 cycles took 9 GB)."""

BROKEN_PIPE_STATUS = 128 + 13
"""Exit status when the reader closes the pipe early, as a shell reports a tool killed by SIGPIPE."""

INTERRUPTED_STATUS = 128 + 2
"""Exit status after Ctrl-C (SIGINT)."""


class CommandLineError(Supi3Error, ValueError):
    """Bad input the command line finds itself: an output path that cannot be written, a failed write."""


class UsageError(CommandLineError):
    """A command line argparse cannot parse; the message is the whole error line, program name included."""


class StdoutError(CommandLineError):
    """Standard output cannot be written (a full disk, a device error); a closed pipe is not one of these."""


# ------------------------------------------------------------------------------------------------------------
# Output: stand-ins for characters stdout cannot encode, JSON, output paths
# ------------------------------------------------------------------------------------------------------------

_STAND_INS = {"µ": "u", "μ": "u", "Ω": "Ohm", "°": "deg", "±": "+/-", "×": "x", "–": "-", "—": "-", "…": "...",
              "‘": "'", "’": "'", "“": '"', "”": '"', "→": "->", "≤": "<=", "≥": ">=", "\u00a0": " "}
_STAND_IN_ERRORS = "supi3.stand-in"


def _stand_in(exc: UnicodeError) -> tuple[str, int]:
    """Codec error handler: an ASCII stand-in for each character the stream cannot encode (``?`` if none)."""
    if not isinstance(exc, UnicodeEncodeError):
        raise exc
    out = []
    for char in exc.object[exc.start:exc.end]:
        stand_in = _STAND_INS.get(char)
        if stand_in is None:
            stand_in = unicodedata.normalize("NFKD", char).encode("ascii", "ignore").decode("ascii") or "?"
        out.append(stand_in)
    return "".join(out), exc.end


codecs.register_error(_STAND_IN_ERRORS, _stand_in)


class _Stdout:
    """What ``sys.stdout`` is while :func:`main` runs: the real stream, with stand-ins for characters it cannot
    encode and a :class:`StdoutError` for a failed write (a closed pipe stays a ``BrokenPipeError``)."""

    def __init__(self, stream: TextIO) -> None:
        self.stream = stream
        self.broken = False
        """Set by a closed pipe, even if the caller swallows the error (argparse's ``--help`` does)."""

    def write(self, text: str) -> int:
        try:
            try:
                return self.stream.write(text)
            except UnicodeEncodeError:
                encoding = self.stream.encoding or "utf-8"
                return self.stream.write(text.encode(encoding, _STAND_IN_ERRORS).decode(encoding))
        except BrokenPipeError:
            self.broken = True
            raise
        except OSError as exc:
            raise StdoutError(f"cannot write to standard output: {exc.strerror or exc}") from exc

    def flush(self) -> None:
        try:
            self.stream.flush()
        except BrokenPipeError:
            self.broken = True
            raise
        except OSError as exc:
            raise StdoutError(f"cannot write to standard output: {exc.strerror or exc}") from exc

    def __getattr__(self, name: str) -> object:
        return getattr(self.stream, name)


def _fits_stdout(text: str) -> bool:
    encoding = getattr(sys.stdout, "encoding", None) or "utf-8"
    try:
        text.encode(encoding)
    except (UnicodeEncodeError, LookupError):
        return False
    return True


def _json_escape(char: str) -> str:
    if ord(char) < 0x80:
        return char
    units = char.encode("utf-16-be", "surrogatepass")
    return "".join(f"\\u{int.from_bytes(units[i:i + 2], 'big'):04x}" for i in range(0, len(units), 2))


def json_for_stdout(text: str) -> str:
    """JSON text as stdout can take it: unchanged, or with every non-ASCII character as a ``\\u`` escape
    (outside strings JSON is ASCII, so this is ``ensure_ascii`` applied afterwards, and lossless)."""
    return text if _fits_stdout(text) else "".join(map(_json_escape, text))


def print_json(data: object) -> None:
    """Print ``data`` as indented JSON, escaped if stdout cannot encode it (:func:`json_for_stdout`)."""
    print(json_for_stdout(json.dumps(data, indent=2, ensure_ascii=False)))


def _cannot(option: str, text: str, reason: str) -> CommandLineError:
    return CommandLineError(f"cannot write {_shown(text)} ({option}): {reason}")


def _check_folder(option: str, text: str, path: Path) -> None:
    folder = path.parent
    if not folder.exists():
        raise _cannot(option, text, f"folder {_shown(str(folder))} does not exist")
    if not folder.is_dir():
        raise _cannot(option, text, f"{_shown(str(folder))} is not a directory")


def output_file(option: str, text: str) -> Path:
    """The file path given to ``option``, checked before any work is done.

    It must be non-empty, not a directory, in an existing folder (folders are not created) and creatable there
    (a probe file is made and removed at once); an existing file must be writable. A device such as ``/dev/full``
    passes: its failure shows when it is written, through :func:`write_output`.

    Raises
    ------
    CommandLineError
        Saying which path, for which option, and why.
    """
    if not text:
        raise CommandLineError(f"{option} must be a file path, not ''")
    if text.endswith(("/", os.sep)):  # Path() would drop the slash and write a file where a folder was meant
        raise _cannot(option, text, "ends with a slash: give a file path")
    path = Path(text)
    try:
        if path.is_dir():
            raise _cannot(option, text, "is a directory")
        _check_folder(option, text, path)
        if path.exists():
            if not os.access(path, os.W_OK):
                raise _cannot(option, text, "permission denied")
        else:
            try:
                os.close(os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
            except FileExistsError:  # a dangling symbolic link, or made meanwhile: writing will tell
                pass
            else:
                path.unlink()
    except OSError as exc:
        raise _cannot(option, text, exc.strerror or str(exc)) from None
    return path


def output_dir(option: str, text: str) -> Path:
    """The directory path given to ``option``, checked before any work: an existing writable directory, or a new
    one that can be made in an existing folder (a probe directory is made and removed at once)."""
    if not text:
        raise CommandLineError(f"{option} must be a directory path, not ''")
    path = Path(text)
    try:
        if path.exists():
            if not path.is_dir():
                raise _cannot(option, text, "exists and is not a directory")
            if not os.access(path, os.W_OK | os.X_OK):
                raise _cannot(option, text, "permission denied")
        else:
            _check_folder(option, text, path)
            path.mkdir()
            path.rmdir()
    except OSError as exc:
        raise _cannot(option, text, exc.strerror or str(exc)) from None
    return path


def write_output(option: str, path: Path, text: str) -> None:
    """Write ``text`` to ``path`` (UTF-8); a failed write is a :class:`CommandLineError`."""
    try:
        path.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise _cannot(option, str(path), exc.strerror or str(exc)) from None


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
        print_json([{"table": f"Table {r.table}", "c": r.c, "mfp": r.mfp, "length_code": r.length_code,
                     "data_length": _length_text(r.length_code), "id_code": f"{r.id_code:02X}",
                     "function": r.function} for r in rows])
        return
    print(_format_rows(
        ("Table", "C[4..0]", "MFP[15..12]", "ID12..8", "Data length", "ID", "Function"),
        [(r.table, r.c, r.mfp or "-", r.length_code, _length_text(r.length_code), f"{r.id_code:02X}h", r.function)
         for r in rows],
    ))


def serial_io_summary(config: DeviceConfig) -> dict[str, Any] | None:
    """The SPI master modes' access sequence and peripheral wiring (3.3, Tables 3-3 and 3-4); None in other modes."""
    mode = config.mfp_mode
    if mode.kind is not MfpKind.SPI_MASTER:
        return None
    seq = serial_io.sequence(mode.direction, mode.width, config.bit_rate)
    uses = {"in": seq.read is not None, "out": seq.write is not None}
    return {
        "sclk_hz": tables.CLOCK_HZ // serial_io.t0_clocks(config.bit_rate),
        "frame_s": seq.frames[0].length / tables.CLOCK_HZ,
        "sequence_s": seq.length / tables.CLOCK_HZ,
        "wiring": [{"pin": f"MFP{w.mfp}", "signal": w.signal,
                    "connect": "; ".join(text for text, side in ((w.inputs, "in"), (w.outputs, "out"))
                                         if text and uses[side]) or "-"}
                   for w in serial_io.WIRING],
    }  # fmt: skip


def describe_config(config: DeviceConfig) -> str:
    """A human-readable description of a decoded configuration."""
    d = config.as_dict()
    lines = [f"{key:20} {value}" for key, value in d.items()]
    pins = ", ".join(f"MFP{p.pin}={p.signal}({p.direction.value})" for p in config.mfp_pins)
    lines.append(f"{'mfp_pins':20} {pins or '-'}")
    serial = serial_io_summary(config)
    if serial is not None:
        lines.append(f"{'serial_io':20} SCLK {serial['sclk_hz'] / 1e6:g} MHz, "
                     f"/SS frame {serial['frame_s'] * 1e6:g} µs, "
                     f"sequence after each data cycle {serial['sequence_s'] * 1e6:g} µs (3.3, Table 3-4)")
        lines.append("peripheral wiring (Table 3-3; MFP0-2 and MFP8-11 to GND):")
        lines.extend(f"  {w['pin']:6} {w['signal']:7} {w['connect']}" for w in serial["wiring"])
    return "\n".join(lines)


def cmd_decode(args: argparse.Namespace) -> None:
    """Decode pin straps into a configuration."""
    config = decode(args.c, args.mfp, args.rf, args.clk_conf, args.diag_conf, args.variant)
    if args.json:
        data = config.as_dict()
        data["mfp_pins"] = [{"pin": p.pin, "signal": p.signal, "direction": p.direction.value}
                            for p in config.mfp_pins]
        serial = serial_io_summary(config)
        if serial is not None:
            data["serial_io"] = serial
        print_json(data)
    else:
        print(describe_config(config))


def cmd_regmap(args: argparse.Namespace) -> None:
    """Render the register map."""
    from supi3.regmap import render

    option = "-o/--output"
    if args.format == "html":
        folder = None if args.output is None else output_dir(option, args.output)
        try:
            render("html", folder)
        except ModuleNotFoundError as exc:  # a plain install: the exporters are the docs extra
            raise CommandLineError(f"--format html needs the docs extra, pip install 'supi3[docs]' ({exc})") from None
        except OSError as exc:
            raise _cannot(option, str(folder), exc.strerror or str(exc)) from None
        print(f"wrote {folder}")
        return
    out = None if args.output is None else output_file(option, args.output)
    text = render(args.format)
    if out is None:
        sys.stdout.write(json_for_stdout(text) if args.format == "json" else text)
    else:
        write_output(option, out, text)
        print(f"wrote {out}")


def cmd_timing(args: argparse.Namespace) -> None:
    """Data cycle time, CPU access time, I/O access window, optical length; optionally a timing table."""
    bit_rate = _parse_bit_rate(args.bit_rate)
    n_bytes = check_int("--bytes", args.bytes, 0, MAX_NETWORK_BYTES,
                        f"{timing.MAX_DEVICES} devices of at most 32 words")
    devices = check_int("--devices", args.devices, 1, timing.MAX_DEVICES, "the INTERBUS limit")
    check_int("--bytes", n_bytes, 0, devices * timing.MAX_DEVICE_BYTES,
              f"--devices {devices} of at most 32 words, Table 3-11 and A23")
    if args.optical_count is not None:
        check_int("--optical-count", args.optical_count, 0, timing.max_optical_count(bit_rate),
                  "a 20 km path there and back at --bit-rate, Table 1-5 and OPT-1")
    data = timing.report(n_bytes, bit_rate, devices)
    if args.optical_count is not None:
        length = timing.optical_length_m(args.optical_count, bit_rate)
        data["optical_count"] = args.optical_count
        data["optical_length_m"] = length
    if args.table:
        data["table"] = [
            {"symbol": r.symbol, "explanation": r.explanation,
             "min_ns": None if r.minimum_s is None else round(r.minimum_s * 1e9, 3),
             "max_ns": None if r.maximum_s is None else round(r.maximum_s * 1e9, 3)}
            for r in timing.timing_table(args.table, bit_rate, n_bytes)
        ]
    if args.json:
        print_json(data)
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


_MEDIA = {"polymer": optical_length.Medium.POLYMER, "glass": optical_length.Medium.GLASS}
_METRES = re.compile(r"[0-9]+(\.[0-9]+)?")


def metres(text: str) -> float:
    """An argparse type: a length in metres in decimal digits (``150``, ``387.5``; no sign, exponent or ``_``)."""
    if not _METRES.fullmatch(text) or len(text) > _MAX_DIGITS:
        raise argparse.ArgumentTypeError(f"must be metres in decimal digits (e.g. 150 or 387.5), not {_shown(text)}")
    return float(text)


def register_byte(text: str) -> int:
    """An argparse type: a register byte, decimal or ``0x`` hex, 0 to 255."""
    try:
        value = int(text, 16) if text.lower().startswith("0x") else integer(text)
    except (ValueError, argparse.ArgumentTypeError):
        raise argparse.ArgumentTypeError(f"must be a byte, decimal or 0x hex, not {_shown(text)}") from None
    if not 0 <= value <= 0xFF:
        raise argparse.ArgumentTypeError(f"must be a byte from 0 to 255, not {_shown(text)}")
    return value


def cmd_optical(args: argparse.Namespace) -> None:
    """Reads 8 and 9 (LENGTH, MEDIUM, ENABLE) to metres and back, and length timer results to codes (OPT-1)."""
    if args.register is not None and args.medium is not None:
        raise CommandLineError("--medium is not for --register: the byte's MEDIUM bit gives the medium (3.4.12)")
    if args.count is None and args.bit_rate is not None:
        raise CommandLineError("--bit-rate is for --count only: a LENGTH code means the same length at both bit "
                               "rates (OPT-1)")
    medium = _MEDIA[args.medium or "polymer"]
    if args.register is not None:
        fields = LENGTH_OUT.decode(args.register)
        medium = optical_length.Medium(fields["MEDIUM"])
        code, enable = fields["LENGTH"], fields["ENABLE"]
    elif args.code is not None:
        code, enable = check_int("--code", args.code, 0, optical_length.LENGTH_MAX_CODE, "LENGTH, 6 bits"), 0
    elif args.metres is not None:
        metres = check_real("--metres", args.metres, 0.0, optical_length.MAX_PATH_M, limit="Table 1-5: 0 m to 20 km")
        code, enable = optical_length.length_code(metres, medium), 0
    else:
        bit_rate = _parse_bit_rate(args.bit_rate or "500k")
        count = check_int("--count", args.count, 0, timing.max_optical_count(bit_rate),
                          "the length timer result n of a 20 km path there and back at --bit-rate, 1.6.1 and OPT-1")
        code, enable = optical_length.timer_code(count, bit_rate, medium), 0
    low, high = optical_length.code_range_m(code, medium)
    register = LENGTH_OUT.encode(LENGTH=code, MEDIUM=int(medium), ENABLE=enable)
    data = {"code": code, "medium": medium.name.lower(), "enable": enable, "register": f"0x{register:02X}",
            "one_way_m_from": low, "one_way_m_below": high,
            "beyond_range": code == optical_length.LENGTH_MAX_CODE}
    if args.json:
        print_json(data)
        return
    for key, value in data.items():
        print(f"{key:16} {value}")


def _parse_bit_rate(text: str) -> int:
    aliases = {"500k": 500_000, "500000": 500_000, "2m": 2_000_000, "2000000": 2_000_000}
    try:
        return aliases[text.lower()]
    except KeyError:
        raise timing.TimingError(f"--bit-rate must be 500k or 2M (Table 1-7), not {_shown(text)}") from None


def regmap_summary() -> str:
    """One line per address of the register map: what a write and a read reach, and how."""
    from supi3.regmap import REGISTER_MAP, AccessDirection

    rows = []
    for address in REGISTER_MAP.addresses:
        cells: list[object] = [address]
        for direction in (AccessDirection.WRITE, AccessDirection.READ):
            port = REGISTER_MAP.port(address, direction)
            name = port.register.name if port.register else ""
            cells += [f"{port.title} ({name})" if name else port.title, port.access.value]
        rows.append(cells)
    return _format_rows(("Addr", "Write", "Access", "Read", "Access"), rows)


def cmd_demo(args: argparse.Namespace) -> None:
    """A master and a small ring, live (with ``--analog``: an SPI ADC and DAC behind a SUPI 3, manual 3.3);
    optionally the pin-level run as a VCD."""
    from supi3 import demo

    clk_conf = tables.clk_conf_for(_parse_bit_rate(args.bit_rate))
    if args.optical:
        if args.analog or args.vcd is not None:
            raise CommandLineError("demo --optical takes neither --analog nor --vcd")
        cycles = check_int("--cycles", demo.OPTICAL_CYCLES if args.cycles is None else args.cycles, 1,
                           MAX_DEMO_CYCLES, "a demo")  # fmt: skip
        plot = None if args.plot is None else output_file("--plot", args.plot)  # before the run, not after it
        for line in demo.run_optical(cycles, plot, clk_conf):
            print(line)
        return
    if args.plot is not None:
        raise CommandLineError("--plot is for demo --optical only")
    cycles = check_int("--cycles", DEMO_CYCLES if args.cycles is None else args.cycles, 1, MAX_DEMO_CYCLES, "a demo")
    if args.vcd is not None:
        check_int("--cycles", cycles, 1, MAX_VCD_CYCLES, "with --vcd: the pin-level run keeps every clock")
    vcd = None if args.vcd is None else output_file("--vcd", args.vcd)  # before the run, not after it
    for line in (demo.run_analog if args.analog else demo.run)(cycles, vcd, clk_conf):
        print(line)
    if not args.analog:
        print("\nRegister map of the serial µP interface (Table 3-10; `supi3 regmap` for all formats):\n")
        print(regmap_summary())


def cmd_campaign(args: argparse.Namespace) -> None:
    """A seeded fault campaign at transaction and/or pin level (supi3.campaign); exit status 1 if a goal is missed."""
    results = [campaign.run_campaign(config) for config in _campaign_configs(args)]
    print(campaign.campaign_report(results, args.json))
    if not all(r.ok for r in results):
        raise SystemExit(1)


def _campaign_arguments(parser: argparse.ArgumentParser) -> None:
    """The campaign's command-line options."""
    parser.add_argument("--cycles", type=integer, default=2000,
                        help=f"master cycles at transaction level, 1 to {campaign.MAX_CYCLES['ring']} (default 2000)")
    parser.add_argument("--pin-cycles", type=integer, default=200,
                        help=f"master cycles at pin level, 1 to {campaign.MAX_CYCLES['pin']} (default 200)")
    parser.add_argument("--seed", type=integer, default=1, help="seed of the campaign (default 1)")
    parser.add_argument("--devices", type=integer, default=8, help="ring size at transaction level (1..64, default 8)")
    parser.add_argument("--pin-devices", type=integer, default=3, help="chips at pin level (1..8, default 3)")
    parser.add_argument("--fidelity", choices=[*campaign.FIDELITIES, "both"], default="both",
                        help="ring (transaction level), pin (cycle-accurate chips) or both (default)")  # fmt: skip
    parser.add_argument("--mix", metavar="EVENT=W,...",
                        help=f"event weights; ring: {', '.join(campaign.RING_EVENTS)}; "
                             f"pin: {', '.join(campaign.PIN_EVENTS)} "
                             "(with --fidelity both, events of the other fidelity are ignored; each fidelity needs "
                             "one)")  # fmt: skip
    parser.add_argument("--json", action="store_true", help="print the results as JSON")


def _campaign_configs(args: argparse.Namespace) -> list[campaign.CampaignConfig]:
    """The campaigns the options ask for."""
    check_int("--cycles", args.cycles, 1, campaign.MAX_CYCLES["ring"], campaign.CYCLE_LIMITS)
    check_int("--pin-cycles", args.pin_cycles, 1, campaign.MAX_CYCLES["pin"], campaign.CYCLE_LIMITS)
    check_int("--devices", args.devices, 1, campaign.MAX_DEVICES["ring"], campaign.DEVICE_LIMITS["ring"])
    check_int("--pin-devices", args.pin_devices, 1, campaign.MAX_DEVICES["pin"], campaign.DEVICE_LIMITS["pin"])
    fidelities: list[campaign.Fidelity] = ["ring", "pin"] if args.fidelity == "both" else [args.fidelity]
    mix = campaign.parse_mix(args.mix) if args.mix is not None else None  # "" is no mix: refused, not the default
    unknown = sorted(set(mix or ()) - set(campaign.RING_EVENTS) - set(campaign.PIN_EVENTS))
    if unknown:
        known = dict.fromkeys(campaign.RING_EVENTS + campaign.PIN_EVENTS)  # "reset" is in both
        raise fail("--mix event", f"one of {', '.join(known)}", unknown[0])
    configs = []
    for fidelity in fidelities:
        own = None
        if mix is not None:
            events = campaign.RING_EVENTS if fidelity == "ring" else campaign.PIN_EVENTS
            own = {e: w for e, w in mix.items() if e in events or args.fidelity != "both"}
            if not own:  # A27: not the fidelity's default mix, a silent guess
                raise fail("--mix", f"an event the {fidelity} campaign runs ({', '.join(events)}) with --fidelity "
                           f"both", args.mix)  # fmt: skip
        ring = fidelity == "ring"
        configs.append(campaign.CampaignConfig(args.cycles if ring else args.pin_cycles, args.seed,
                                      args.devices if ring else args.pin_devices, fidelity, own))  # fmt: skip
    return configs


FIGURES_DIR = "docs/figures"
"""``figures -o`` default: where the source tree keeps the redrawn figures (``docs/figures.md``)."""


def cmd_figures(args: argparse.Namespace) -> None:
    """Redraw the manual's serial I/O, µP interface and register expansion figures from model traces (WaveJSON, SVG,
    VCD)."""
    from supi3.figures import write_figures

    option = "-o/--output"
    folder = output_dir(option, args.output)
    try:
        written = write_figures(folder, vcd=args.vcd)
    except ModuleNotFoundError as exc:  # a plain install: wavedrom is the docs extra; checked before any write
        if exc.name != "wavedrom":
            raise
        raise CommandLineError("figures needs the docs extra, pip install 'supi3[docs]' "
                               "(the wavedrom package renders the SVG)") from None
    except OSError as exc:
        raise _cannot(option, str(folder), exc.strerror or str(exc)) from None
    for path in written:
        print(f"wrote {path}")


def cmd_sdk(args: argparse.Namespace) -> None:
    """Print where the C firmware SDK is and how to compile it (docs/sdk.md), like ``pybind11 --includes``."""
    from supi3 import sdk

    if args.includes:
        print(sdk.includes())
    elif args.sources:
        print(" ".join(shlex.quote(str(path)) for path in sdk.sources()))
    elif args.cflags:
        print(sdk.cflags())
    else:
        print(sdk.SDK_DIR)


FIRMWARE_STOPPED_STATUS = 3
"""``firmware run``: the firmware faulted, hung, used up its instruction budget, or the bench could not go on."""

FIRMWARE_FAILED_STATUS = 4
"""``firmware run``: the run ended, but the firmware broke an interface rule or the process data did not arrive."""

MAX_FIRMWARE_CYCLES = 100_000
"""``firmware run --cycles`` limit (about 6 s of bus time at 500 kbit/s)."""

MAX_PIN_FIRMWARE_CYCLES = MAX_VCD_CYCLES
"""``firmware run --cycles`` limit with ``--fidelity pin``: every chip clock is a step of the pin-level chip (about
0.5 s of wall time a cycle at 500 kbit/s), and with ``--vcd`` every pin of every clock is kept, as ``demo --vcd``."""


_FIRMWARE_DATA_OPTIONS = {"out_data": "--out", "in_data": "--in"}
"""``run_firmware``'s data arguments and their options: an argument error names the option (MCU-49)."""


def _firmware_extra() -> None:
    """Refuse ``firmware`` without the firmware extra (unicorn, pyelftools, ziglang), one line, before any work."""
    import importlib.util

    missing = [name for name in ("unicorn", "elftools") if importlib.util.find_spec(name) is None]
    if missing:
        raise CommandLineError(f"firmware needs the firmware extra, pip install 'supi3[firmware]' (missing: "
                               f"{', '.join(missing)})")  # fmt: skip


def cmd_firmware_run(args: argparse.Namespace) -> None:
    """Run a firmware ELF on the emulated board against the chip and report (docs/firmware-in-the-loop.md)."""
    _firmware_extra()
    from supi3.mcu.board import MAX_CPU_HZ
    from supi3.mcu.session import MAX_PIN_DEVICES, MIN_CYCLES, MIN_CYCLES_LIMIT, run_firmware
    from supi3.spi.upif import Mode

    if not Path(args.firmware).is_file():
        reason = "not a file" if Path(args.firmware).exists() else "no such file"
        raise CommandLineError(f"FIRMWARE must be an ELF file, not {_shown(args.firmware)} ({reason})")
    pin = args.fidelity == "pin"
    if args.vcd is not None and not pin:
        raise CommandLineError("--vcd needs --fidelity pin (the transaction-level chip has no pins)")
    check_int("--cycles", args.cycles, MIN_CYCLES, MAX_PIN_FIRMWARE_CYCLES if pin else MAX_FIRMWARE_CYCLES,
              MIN_CYCLES_LIMIT + ("; with --fidelity pin: every chip clock is stepped" if pin else ""))  # fmt: skip
    check_int("--cpu-hz", args.cpu_hz, 1_000_000, MAX_CPU_HZ, "the STM32F10x's highest SYSCLK, RM0008 7.2; MCU-50")
    check_int("--devices", args.devices, 1, MAX_PIN_DEVICES if pin else 64,
              "with --fidelity pin: each further chip is stepped with it" if pin else "")  # fmt: skip
    check_int("--max-instructions", args.max_instructions, 1000, 10**10)
    mfp = args.mfp if args.mfp is not None or args.c != DEFAULT_STRAPS[0] else DEFAULT_STRAPS[1]
    vcd = None if args.vcd is None else output_file("--vcd", args.vcd)  # before the run, not after it
    try:
        report = run_firmware(args.firmware, cpu=args.cpu, cpu_hz=float(args.cpu_hz), straps=(args.c, mfp),
                              bit_rate=_parse_bit_rate(args.bit_rate), devices=args.devices, cycles=args.cycles,
                              out_data=args.out_data, in_data=args.in_data, max_instructions=args.max_instructions,
                              fidelity=args.fidelity, vcd=vcd, mode=Mode(args.mode))  # fmt: skip
    except ArgumentError as exc:  # MCU-49: --out or --in of another length than the firmware's configuration's
        option = _FIRMWARE_DATA_OPTIONS.get(exc.name)
        if option is None:
            raise
        raise CommandLineError(option + str(exc).removeprefix(exc.name)) from None
    except OSError as exc:
        raise CommandLineError(f"cannot write {_shown(str(vcd))} (--vcd): {exc.strerror or exc}") from None
    if args.json:
        print_json(report.as_dict())
    else:
        print(report)
    if report.stop is not None or report.error is not None:
        raise SystemExit(FIRMWARE_STOPPED_STATUS)
    if report.failed:
        raise SystemExit(FIRMWARE_FAILED_STATUS)


def cmd_firmware_build(args: argparse.Namespace) -> None:
    """Build a firmware for the emulated board with the SDK's driver and board port (supi3.mcu.build)."""
    _firmware_extra()
    from supi3.mcu.build import MACRO_NAME, BuildError, build

    out = output_file("-o/--output", args.output)
    defines = {}
    for text in args.defines:
        name, _, value = text.partition("=")
        if not MACRO_NAME.fullmatch(name) or any(c in value for c in "\r\n\0"):  # a line break ends the macro
            raise CommandLineError(f"-D must be NAME or NAME=VALUE with a C identifier NAME and a one-line VALUE, "
                                   f"not {_shown(text)}")
        defines[name] = value if _ else "1"
    try:
        print(build(args.sources, out, cpu=args.cpu, defines=defines))
    except BuildError as exc:
        if not exc.output:
            raise
        # The compiler's messages as it wrote them, line by line; then the one error line.
        with contextlib.suppress(OSError, ValueError):
            sys.stderr.write(exc.output if exc.output.endswith("\n") else exc.output + "\n")
        raise CommandLineError(f"{exc.summary} (the compiler's messages above)") from None


def hex_bytes(text: str) -> bytes:
    """An argparse type: bytes in hex digits, optionally spaced (``1234``, ``12 34``), at most 32 bytes."""
    try:
        data = bytes.fromhex(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be bytes in hex digits (e.g. 1234), not {_shown(text)}") from None
    if not 1 <= len(data) <= 32:
        raise argparse.ArgumentTypeError(f"must be 1 to 32 bytes, not {len(data)}")
    return data


_INTEGER = re.compile(r"[+-]?[0-9]+", re.ASCII)
_MAX_DIGITS = 4000
"""Longer integers are refused unread: far beyond every limit, and ``int()`` refuses 4300 digits anyway."""


def integer(text: str) -> int:
    """An argparse type: a plain decimal integer (ASCII digits, an optional sign; no spaces, ``_``, ``1e3``)."""
    if not _INTEGER.fullmatch(text):
        raise argparse.ArgumentTypeError(f"must be an integer in decimal digits, not {_shown(text)}")
    if len(text) > _MAX_DIGITS:
        raise argparse.ArgumentTypeError(f"must be an integer of at most {_MAX_DIGITS} digits, not {_shown(text)}")
    return int(text)


def positive_integer(text: str) -> int:
    """An argparse type: a decimal integer from 1 up (counts, repeats, steps; :func:`integer`'s digits)."""
    value = integer(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a whole number from 1 up, not {_shown(text)}")
    return value


class _Parser(argparse.ArgumentParser):
    """An argument parser whose usage errors are one :class:`UsageError` line, like every other supi3 error, and
    which takes options only spelt out in full."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> NoReturn:
        raise UsageError(f"{self.prog}: error: {message} (see {self.prog} --help)")


_DESCRIPTION = ("The IBS SUPI 3 OPC INTERBUS slave chip: operating modes, pin-strap decoding, register map, "
                "timing, a demo, and the manual's serial-interface figures redrawn.")
_EPILOG = """exit status: 0 done; 2 bad input (one line on stderr); 141 output pipe closed early (quiet);
130 interrupted; 3 and 4 (firmware run) the firmware stopped or broke a rule; 1 an internal error (a traceback:
please report it)"""


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``supi3`` command."""
    parser = _Parser(prog="supi3", description=_DESCRIPTION, epilog=_EPILOG,
                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("demo", help="a master and a small ring, live (built-in defaults)")
    p.add_argument("--cycles", type=integer, default=None, metavar="N",
                   help=f"data cycles to run, 1 to {MAX_DEMO_CYCLES}, to {MAX_VCD_CYCLES} with --vcd (default "
                        f"{DEMO_CYCLES}; with --optical, the whole scenario)")
    p.add_argument("--vcd", metavar="PATH", help="also run the SUPI 3 chips at pin level and write a VCD")
    p.add_argument("--bit-rate", default="500k", help="500k or 2M")
    p.add_argument("--analog", action="store_true",
                   help="an analog I/O device instead: a SUPI 3 in SPI 16 IN/16 OUT with an SPI ADC and DAC (3.3); "
                        "with --vcd its SPI pins are checked against Table 3-4")
    p.add_argument("--optical", action="store_true",
                   help="a ring of SUPI 3 OPC chips joined by fibre instead (1.6): optical initialization, the "
                        "master's optical diagnostic table, a bent fibre and a pulled connector")
    p.add_argument("--plot", metavar="PATH",
                   help="with --optical: write the disturbed path's power levels over time (HTML with SVG)")
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
    p.add_argument("--bytes", type=integer, default=4, metavar="N",
                   help=f"data bytes in the whole network, 0 to 64 per device, {MAX_NETWORK_BYTES} at most (default 4)")
    p.add_argument("--devices", type=integer, default=1, metavar="N",
                   help=f"devices in the ring, 1 to {timing.MAX_DEVICES} (default 1)")
    p.add_argument("--optical-count", type=integer, metavar="N",
                   help=f"length timer result n, 0 to {timing.max_optical_count(500_000)} at 500k, to "
                        f"{MAX_OPTICAL_COUNT} at 2M (20 km there and back; 1.6.1, Table 1-5, OPT-1)")
    p.add_argument("--table", choices=sorted(timing.TIMING_TABLES), help="also evaluate a timing table")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_timing)

    p = sub.add_parser("optical", help="optical path length: register reads 8/9 <-> metres and medium (OPT-1)")
    what = p.add_mutually_exclusive_group(required=True)
    what.add_argument("--register", type=register_byte, metavar="BYTE",
                      help="a read 8 or 9 byte (LENGTH, MEDIUM, ENABLE; 3.4.12) to decode")
    what.add_argument("--code", type=integer, metavar="N", help="a LENGTH code, 0 to 63, to turn into metres")
    what.add_argument("--metres", type=metres, metavar="M", help="a one-way path length to turn into its code")
    what.add_argument("--count", type=integer, metavar="N",
                      help=f"a length timer result n (1.6.1) at --bit-rate, 0 to {timing.max_optical_count(500_000)} "
                           f"at 500k, to {MAX_OPTICAL_COUNT} at 2M (20 km there and back)")
    p.add_argument("--medium", choices=sorted(_MEDIA),
                   help="fibre medium for --code, --metres, --count (default polymer; a register byte has its own)")
    p.add_argument("--bit-rate", help="500k (default) or 2M, for --count only")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_optical)

    p = sub.add_parser("campaign", help="a seeded fault campaign: error locations, latches, recovery, memory")
    _campaign_arguments(p)
    p.set_defaults(func=cmd_campaign)

    p = sub.add_parser("figures", help="redraw the manual's serial I/O, µP interface and register expansion figures "
                                       "(needs the docs extra)")
    p.add_argument("-o", "--output", metavar="DIR", default=FIGURES_DIR,
                   help=f"folder to write WaveJSON and SVG into (default {FIGURES_DIR})")
    p.add_argument("--vcd", action="store_true", help="also write a VCD per µP interface figure")
    p.set_defaults(func=cmd_figures)

    p = sub.add_parser("sdk", help="paths and flags of the C firmware SDK (docs/sdk.md)")
    what = p.add_mutually_exclusive_group(required=True)
    what.add_argument("--includes", action="store_true", help="the -I flag for supi3.h and supi3_regs.h")
    what.add_argument("--sources", action="store_true", help="the driver's C sources")
    what.add_argument("--cflags", action="store_true", help="-std=c99, the warning flags and the -I flag")
    what.add_argument("--dir", action="store_true", help="the SDK folder (include/, src/, CMakeLists.txt)")
    p.set_defaults(func=cmd_sdk)

    firmware = sub.add_parser("firmware", help="a firmware binary on the emulated board against the chip (needs the "
                                               "firmware extra; docs/firmware-in-the-loop.md)")  # fmt: skip
    steps = firmware.add_subparsers(dest="step", required=True)
    p = steps.add_parser("run", help="run a firmware ELF on the default bench and report",
                         epilog=f"exit status: 0 clean; {FIRMWARE_STOPPED_STATUS} the firmware faulted, hung or used "
                                f"up its budget; {FIRMWARE_FAILED_STATUS} an interface violation, process data "
                                "that did not arrive or a main loop that did not serve the last cycle; "
                                "2 bad input")  # fmt: skip
    p.add_argument("firmware", metavar="FIRMWARE.elf", help="built for the board port (supi3 firmware build)")
    p.add_argument("--cpu", choices=["cortex_m3", "cortex_m0"], default="cortex_m3")
    p.add_argument("--cpu-hz", type=integer, default=48_000_000, metavar="HZ",
                   help="core clock, 1 MHz to 72 MHz, the STM32F10x's highest (default 48000000, the board port's "
                        "BOARD_SYSCLK_HZ: its busy waits count cycles of that clock, so build the firmware with "
                        "-D BOARD_SYSCLK_HZ=HZ for another)")
    p.add_argument("--c", default=DEFAULT_STRAPS[0], metavar="BITS",
                   help=f"the chip's C[4..0] straps, an Init-µP mode (default {DEFAULT_STRAPS[0]})")
    p.add_argument("--mfp", metavar="BITS",
                   help=f"MFP[15..12], for the modes with configuration expansion (default {DEFAULT_STRAPS[1]} with "
                        "the default C[4..0], else unset)")  # fmt: skip
    p.add_argument("--bit-rate", default="500k", help="500k or 2M")
    p.add_argument("--devices", type=integer, default=1, metavar="N",
                   help="devices in the ring, the chip first, 1 to 64, fewer with --fidelity pin (default 1)")
    p.add_argument("--cycles", type=integer, default=10, metavar="N",
                   help=f"master cycles in all, 6 (the power-up's 3 and 3 to check the exchange) to "
                        f"{MAX_FIRMWARE_CYCLES} (default 10)")
    p.add_argument("--max-instructions", type=integer, default=20_000_000, metavar="N",
                   help="instruction budget of the power-up and of the exchange (default 20000000)")
    p.add_argument("--out", dest="out_data", type=hex_bytes, metavar="HEX",
                   help="the master's OUT data, as many bytes as the chip's data as the firmware configures it "
                        "(checked when the master has read it, after the power-up)")
    p.add_argument("--in", dest="in_data", type=hex_bytes, metavar="HEX",
                   help="the firmware's input terminals, as many bytes as --out")
    p.add_argument("--fidelity", choices=["transaction", "pin"], default="transaction",
                   help="the chip: transaction level (default), or the pin-level whole chip with SPI1 and the GPIO "
                        "pins on its MFP pins, Table 3-7 checked by the chip (1 device, up to "
                        f"{MAX_PIN_FIRMWARE_CYCLES} cycles)")  # fmt: skip
    p.add_argument("--vcd", metavar="PATH", help="with --fidelity pin: write the chip's pins and the MCU's lines")
    p.add_argument("--mode", choices=["motorola", "intel"], default="motorola",
                   help="the board's wiring for the interface the firmware initializes: motorola (SPI, default) or "
                        "intel (S/R on PB0, Ser_IN/OUT half duplex; build with -D FW_MODE=SUPI3_MODE_INTEL)")
    p.add_argument("--json", action="store_true")
    p.set_defaults(func=cmd_firmware_run)

    p = steps.add_parser("build", help="build a firmware with the SDK's driver and board port (ziglang)")
    p.add_argument("sources", nargs="+", metavar="SOURCE.c", help="the firmware's .c files")
    p.add_argument("-o", "--output", required=True, metavar="PATH", help="the ELF to write")
    p.add_argument("--cpu", choices=["cortex_m3", "cortex_m0"], default="cortex_m3")
    p.add_argument("-D", dest="defines", action="append", default=[], metavar="NAME=VALUE",
                   help="a macro, e.g. -D BOARD_SPI_BR=3u")
    p.set_defaults(func=cmd_firmware_build)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``supi3`` command: run it and return the exit status (see the module docstring).

    Bad input (a usage error or any :class:`~supi3.errors.Supi3Error`) is one line on stderr and status 2; a
    closed output pipe is status 141, quietly; Ctrl-C is 130; any other exception is a bug and propagates with its
    traceback. While it runs, ``sys.stdout`` gives stand-ins for characters it cannot encode.
    """
    stream = sys.stdout
    if stream is not None:
        sys.stdout = _Stdout(stream)
    try:
        return _run(argv)
    finally:
        sys.stdout = stream


def _run(argv: Sequence[str] | None) -> int:
    try:
        try:
            args = build_parser().parse_args(argv)
            args.func(args)
        finally:
            if sys.stdout is not None:
                sys.stdout.flush()  # a closed pipe or a full disk shows here, not at interpreter exit
    except SystemExit as exc:  # --help, or argparse's own exit
        if _pipe_closed():
            return BROKEN_PIPE_STATUS
        return exc.code if isinstance(exc.code, int) else 0 if exc.code is None else 1
    except BrokenPipeError:
        _silence_stdout()
        return BROKEN_PIPE_STATUS
    except KeyboardInterrupt:
        return INTERRUPTED_STATUS
    except Supi3Error as exc:
        if isinstance(exc, StdoutError):
            _silence_stdout()
        _error_line(str(exc) if isinstance(exc, UsageError) else f"supi3: error: {exc}")
        return 2
    return BROKEN_PIPE_STATUS if _pipe_closed() else 0


def _pipe_closed() -> bool:
    """Whether a write to stdout met a closed pipe (then stdout is silenced)."""
    if isinstance(sys.stdout, _Stdout) and sys.stdout.broken:
        _silence_stdout()
        return True
    return False


def _one_line(text: str) -> str:
    """``text`` with every non-printable character (a newline in a value, a surrogate) as an escape."""
    return "".join(c if c.isprintable() else c.encode("unicode_escape").decode("ascii") for c in text)


def _error_line(text: str) -> None:
    with contextlib.suppress(OSError, ValueError):  # stderr closed too: the status has to do
        print(_one_line(text), file=sys.stderr, flush=True)


def _silence_stdout() -> None:
    """Point file descriptor 1 at the null device, so that what is still buffered for a closed pipe or a full disk
    is dropped at exit instead of raising there (the recipe of Python's ``signal`` documentation)."""
    stream = sys.stdout.stream if isinstance(sys.stdout, _Stdout) else sys.stdout
    try:
        fd = stream.fileno()
        devnull = os.open(os.devnull, os.O_WRONLY)
    except (OSError, ValueError, AttributeError):  # not a real file (captured, in-process): nothing to do
        return
    os.dup2(devnull, fd)
    os.close(devnull)


if __name__ == "__main__":
    sys.exit(main())
