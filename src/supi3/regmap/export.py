"""Every output generated from :data:`~supi3.regmap.registers.REGISTER_MAP`: SystemRDL, HTML, Markdown, C, JSON.

The SystemRDL is compiled with systemrdl-compiler and rendered to HTML by peakrdl-html. Markdown and the C
header are written here: peakrdl-markdown and peakrdl-cheader see registers only, so they lose what the
firmware needs most (the write/read split per address, the accesses that reach no register, the command and
initialization bytes, the reset classes), and peakrdl-cheader describes a memory-mapped struct, which a
serial interface has no use for.
"""

from __future__ import annotations

import json
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any, Final

from supi3.regmap.core import (
    BYTE_BITS,
    Access,
    AccessDirection,
    Assumption,
    ByteLayout,
    Field,
    Port,
    Register,
    RegisterMapError,
    Reset,
)
from supi3.regmap.registers import REGISTER_MAP

GENERATOR: Final[str] = "src/supi3/regmap (python -m supi3.regmap --write-checked-in)"
MANUAL: Final[str] = "IBS SUPI 3 OPC UM E, revision 05, 04/2009"
TITLE: Final[str] = "IBS SUPI 3 OPC serial µP interface"

FORMATS: Final[tuple[str, ...]] = ("html", "md", "rdl", "h", "json")
"""The formats :func:`render` accepts."""

CHECKED_IN: Final[dict[str, Path]] = {
    "md": Path("docs/regmap.md"),
    "h": Path("src/supi3/sdk/c/include/supi3_regs.h"),
}
"""Generated files kept in the repository, by format, relative to the repository root."""

# ----------------------------------------------------------------------------------------------------------------
# Shared views of the map
# ----------------------------------------------------------------------------------------------------------------


def _ports_of(register: Register) -> tuple[Port, ...]:
    return tuple(p for p in REGISTER_MAP.ports if p.register is register)


def _sw(register: Register) -> str:
    """SystemRDL software access of a register: ``w``, ``r`` or ``rw`` (shared write and read storage)."""
    directions = {p.direction for p in _ports_of(register)}
    return "rw" if len(directions) == 2 else ("w" if AccessDirection.WRITE in directions else "r")


def _field_access(register: Register, field: Field) -> str:
    """The access of one field: its own override, else its register's port access (``rw`` when shared)."""
    if field.access is not None:
        return field.access.value
    ports = _ports_of(register)
    return "rw" if len(ports) == 2 else ports[0].access.value


def _bits(field: Field) -> str:
    return str(field.lsb) if field.width == 1 else f"{field.msb}:{field.lsb}"


def _resets(register: Register) -> str:
    return ", ".join(r.value for r in Reset if r in register.cleared_by)


def _reserved_ranges(layout: ByteLayout) -> list[str]:
    """The reserved bits of a layout as ranges, MSB first: ``["6:1"]`` for the initialization byte."""
    ranges: list[str] = []
    bit = BYTE_BITS - 1
    while bit >= 0:
        if layout.mask >> bit & 1:
            bit -= 1
            continue
        msb = bit
        while bit >= 0 and not layout.mask >> bit & 1:
            bit -= 1
        ranges.append(str(msb) if msb == bit + 1 else f"{msb}:{bit + 1}")
    return ranges


def _values_text(field: Field) -> str:
    return "; ".join(f"{v.value:0{field.width}b} = {v.name} ({v.doc.rstrip('.')})" for v in field.values)


def _field_text(field: Field) -> str:
    parts = [field.doc]
    if field.overlays is not None:
        parts.append(f"Overlays {field.overlays}.")
    if field.values:
        parts.append(f"Values: {_values_text(field)}.")
    return " ".join(parts)


def _port_summary(port: Port) -> str:
    if port.register is None:
        return f"{port.title} ({port.access.value})"
    return f"{port.register.name}: {port.title} ({port.access.value})"


def _layouts() -> tuple[ByteLayout, ...]:
    return (REGISTER_MAP.command_byte, REGISTER_MAP.init_byte)


# ----------------------------------------------------------------------------------------------------------------
# SystemRDL
# ----------------------------------------------------------------------------------------------------------------


def _rdl_string(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def _rdl_field(register: Register, field: Field) -> list[str]:
    sw = _sw(register)
    access = field.access or _ports_of(register)[0].access
    props = [f"sw = {sw};", f"hw = {'w' if sw == 'r' else 'r'};"]
    if access is Access.RC and sw == "r":
        props.append("onread = rclr;")
    overlays = [
        f"Bits {_bits(o)} are also {o.name}: {_field_text(o)}" for o in register.fields if o.overlays == field.name
    ]
    desc = " ".join([_field_text(field), *overlays])
    encode = f" encode = {register.name}_{field.name}_e;" if field.values else ""
    return [
        "        field {",
        f"            desc = {_rdl_string(desc)};",
        f"            {' '.join(props)}{encode}",
        f"        }} {field.name}[{field.msb}:{field.lsb}] = {field.width}'h{field.extract(register.reset):X};",
    ]


def _rdl_enum(register: Register, field: Field) -> list[str]:
    lines = [f"    enum {register.name}_{field.name}_e {{"]
    lines += [f"        {v.name} = {field.width}'d{v.value} {{ desc = {_rdl_string(v.doc)}; }};" for v in field.values]
    return [*lines, "    };"]


def _rdl_map_desc() -> str:
    lines = ["Address map (Table 3-10), write | read:", ""]
    lines += [
        f"- {a}: {_port_summary(REGISTER_MAP.port(a, AccessDirection.WRITE))} | "
        f"{_port_summary(REGISTER_MAP.port(a, AccessDirection.READ))}"
        for a in REGISTER_MAP.addresses
    ]
    for layout in _layouts():
        lines += ["", f"{layout.title} ({layout.ref}): {layout.doc}", ""]
        lines += [f"- bit{'s' if f.width > 1 else ''} {_bits(f)} {f.name}: {f.doc}" for f in layout.fields]
        lines += [f"- {c.value:02X}h {c.name}: {c.doc}" for c in layout.constants]
    return "\n".join(lines)


def to_systemrdl() -> str:
    """Return the register map as SystemRDL 2.0 (one ``addrmap``, 8-bit registers).

    A write-only and a read-only register share an address where Table 3-10 names two; ID and SET, which read
    back what was written, are single ``sw = rw`` registers. Addresses that reach no register (4, 5, 6, 15)
    and the command and initialization bytes are described in the ``addrmap`` description. A field that
    overlays another (CL over LENGTH_CODE) is described in the field it overlays.
    """
    lines = [
        f"// {TITLE}: generated from {GENERATOR}. Do not edit.",
        "addrmap supi3 {",
        f"    name = {_rdl_string(TITLE)};",
        f"    desc = {_rdl_string(_rdl_map_desc())};",
        "    default regwidth = 8;",
        "    default accesswidth = 8;",
    ]
    for register in REGISTER_MAP.registers:
        for field in register.base_fields:
            if field.values:
                lines += _rdl_enum(register, field)
        desc = f"{register.doc} Ref: {register.ref}. Cleared by: {_resets(register)} reset.".lstrip()
        lines += [
            "    reg {",
            f"        name = {_rdl_string(register.title)};",
            f"        desc = {_rdl_string(desc)};",
        ]
        for field in register.base_fields:
            lines += _rdl_field(register, field)
        lines.append(f"    }} {register.name} @ 0x{register.address:X};")
    return "\n".join([*lines, "};", ""])


def compile_systemrdl(text: str) -> Any:
    """Compile and elaborate SystemRDL ``text`` with systemrdl-compiler; return the top ``AddrmapNode``.

    Raises
    ------
    RegisterMapError
        If the compiler rejects the text.
    """
    from systemrdl.compiler import RDLCompiler
    from systemrdl.messages import RDLCompileError

    compiler = RDLCompiler()
    with tempfile.TemporaryDirectory() as tmp:
        source = Path(tmp) / "supi3.rdl"
        source.write_text(text, encoding="utf-8")
        try:
            compiler.compile_file(str(source))
            return compiler.elaborate().top
        except RDLCompileError as error:
            raise RegisterMapError(f"systemrdl-compiler rejected the generated SystemRDL: {error}") from error


# ----------------------------------------------------------------------------------------------------------------
# HTML
# ----------------------------------------------------------------------------------------------------------------


def _path(name: str, value: object) -> Path:
    """``value`` if it is a :class:`~pathlib.Path`, else the named error (a string is no path here: no guess)."""
    if not isinstance(value, Path):
        raise RegisterMapError(f"{name} must be a pathlib.Path, not {value!r:.60}")
    return value


def to_html(outdir: Path) -> Path:
    """Write a browsable HTML register map (peakrdl-html, per-register bit diagrams) into ``outdir``.

    Returns
    -------
    Path
        The ``index.html`` of the generated site.
    """
    _path("outdir", outdir)
    from peakrdl_html import HTMLExporter

    outdir.mkdir(parents=True, exist_ok=True)
    exporter = HTMLExporter(generate_source_links=False)
    exporter.export(compile_systemrdl(to_systemrdl()), str(outdir), title=TITLE)
    return outdir / "index.html"


# ----------------------------------------------------------------------------------------------------------------
# JSON
# ----------------------------------------------------------------------------------------------------------------


def _field_json(field: Field) -> dict[str, Any]:
    return {
        "name": field.name,
        "lsb": field.lsb,
        "width": field.width,
        "mask": field.mask,
        "access": None if field.access is None else field.access.value,
        "overlays": field.overlays,
        "doc": field.doc,
        "values": [{"name": v.name, "value": v.value, "doc": v.doc} for v in field.values],
    }


def _layout_json(layout: ByteLayout) -> dict[str, Any]:
    result: dict[str, Any] = {"name": layout.name, "title": layout.title, "ref": layout.ref, "doc": layout.doc}
    if isinstance(layout, Register):
        result |= {"address": layout.address, "reset": layout.reset, "cleared_by": sorted(layout.cleared_by)}
    return result | {
        "mask": layout.mask,
        "fields": [_field_json(f) for f in layout.fields],
        "constants": [{"name": c.name, "value": c.value, "doc": c.doc} for c in layout.constants],
    }


def to_json() -> str:
    """Return the register map as JSON: ports (address x direction), registers and interface bytes."""
    document = {
        "title": TITLE,
        "manual": MANUAL,
        "generator": GENERATOR,
        "address_bits": REGISTER_MAP.address_bits,
        "accesses": {a.value: a.meaning for a in Access},
        "ports": [
            {
                "address": p.address,
                "direction": p.direction.value,
                "access": p.access.value,
                "title": p.title,
                "register": None if p.register is None else p.register.name,
                "clear_on_read_mask": p.clear_on_read_mask,
            }
            for p in REGISTER_MAP.ports
        ],
        "registers": [_layout_json(r) for r in REGISTER_MAP.registers],
        "interface_bytes": [_layout_json(layout) for layout in _layouts()],
    }
    return json.dumps(document, indent=2, ensure_ascii=False) + "\n"


# ----------------------------------------------------------------------------------------------------------------
# Markdown
# ----------------------------------------------------------------------------------------------------------------


def _md_table(header: Iterable[str], rows: Iterable[Iterable[str]]) -> list[str]:
    head = list(header)
    lines = ["| " + " | ".join(head) + " |", "|" + "|".join("---" for _ in head) + "|"]
    return [*lines, *("| " + " | ".join(row) + " |" for row in rows), ""]


def _md_port(port: Port) -> str:
    if port.register is None:
        return f"{port.title} ({port.access.value})"
    return f"[{port.register.name}](#{port.register.name.lower()}) {port.title} ({port.access.value})"


def _reserved_text(layout: ByteLayout) -> str:
    """What to do with reserved bits: write 0 where the byte is written, and they read 0 where it is read."""
    directions = {p.direction for p in _ports_of(layout)} if isinstance(layout, Register) else {AccessDirection.WRITE}
    rules = (["write 0"] if AccessDirection.WRITE in directions else []) + (
        ["reads 0"] if AccessDirection.READ in directions else []
    )
    return f"Reserved: {', '.join(rules)}."


def _md_fields(layout: ByteLayout) -> list[str]:
    register = layout if isinstance(layout, Register) else None
    rows = [
        (_bits(f), f.name, *([_field_access(register, f)] if register else []), _field_text(f)) for f in layout.fields
    ]
    rows += [(bits, "-", *(["-"] if register else []), _reserved_text(layout)) for bits in _reserved_ranges(layout)]
    rows.sort(key=lambda row: -int(row[0].split(":")[0]))
    return _md_table(("Bits", "Field", *(["Access"] if register else []), "Description"), rows)


def to_markdown() -> str:
    """Return the register map as Markdown (checked in as ``docs/regmap.md``)."""
    lines = [
        "# SUPI 3 OPC register map",
        "",
        f"<!-- Generated from {GENERATOR}. Do not edit. -->",
        "",
        f"The {TITLE} ({MANUAL}, 3.4.7, Table 3-10): {len(REGISTER_MAP.addresses)} byte addresses, selected by "
        "A3..0 in the command byte. Every register is 8 bits. Layouts the manual shows only in missing figures "
        "are project decisions, each recorded in [assumptions/regmap.md](assumptions/regmap.md).",
        "",
        "## Address map",
        "",
        *_md_table(
            ("Address", "Write", "Read"),
            (
                (
                    f"{a} ({a:02X}h)",
                    _md_port(REGISTER_MAP.port(a, AccessDirection.WRITE)),
                    _md_port(REGISTER_MAP.port(a, AccessDirection.READ)),
                )
                for a in REGISTER_MAP.addresses
            ),
        ),
        "## Accesses",
        "",
        *_md_table(("Access", "Meaning"), ((f"`{a.value}`", a.meaning) for a in Access)),
        "## Resets",
        "",
        "Every register resets to the value given below (all 00h, 3.4.7).",
        "",
        *_md_table(
            ("Reset", "Registers it clears"),
            ((r.value, ", ".join(x.name for x in REGISTER_MAP.cleared_by(r)) or "none") for r in Reset),
        ),
        "## Registers",
        "",
    ]
    for register in REGISTER_MAP.registers:
        ports = ", ".join(f"{p.direction.value} ({p.access.value})" for p in _ports_of(register))
        lines += [
            f"### {register.name}",
            "",
            f"**{register.title}**: address {register.address} ({register.address:02X}h), {ports}. "
            f"Reset {register.reset:02X}h, cleared by: {_resets(register)}. Ref: {register.ref}.",
            "",
        ]
        if register.doc:
            lines += [register.doc, ""]
        lines += _md_fields(register)
    lines += ["## Interface bytes", ""]
    for layout in _layouts():
        lines += [f"### {layout.name}", "", f"**{layout.title}** ({layout.ref}). {layout.doc}", ""]
        lines += _md_fields(layout)
        lines += _md_table(("Value", "Name", "Meaning"), ((f"{c.value:02X}h", c.name, c.doc) for c in layout.constants))
    return "\n".join(lines).rstrip("\n") + "\n"


# ----------------------------------------------------------------------------------------------------------------
# C header
# ----------------------------------------------------------------------------------------------------------------

_CLine = str | tuple[str, str, str]
"""A header line: text, or a ``(macro, value, comment)`` triple aligned by :func:`_c_join` (comment may be "")."""

_C_VALUE_WIDTH: Final[int] = len("0xFFu")
"""Comments after values up to this wide start in one column."""


def _c_assumptions(assumptions: Iterable[Assumption]) -> str:
    """The comment naming the recorded decisions a macro rests on: ``/* assumption RM-7 */``; "" for none.

    The header's opening comment lists each one with its summary (:func:`_c_assumption_legend`).
    """
    ids = list(dict.fromkeys(a.id for a in assumptions))
    return f"/* assumption{'s' if len(ids) > 1 else ''} {', '.join(ids)} */" if ids else ""


def _all_assumptions() -> list[Assumption]:
    """Every decision a header macro rests on, once each, by area and number (RM-1 .. RM-8, then UP-n)."""
    found: list[Assumption] = []
    for layout in (*_layouts(), *REGISTER_MAP.registers):
        for f in layout.fields:
            found += [*f.assumptions, *(a for v in f.values for a in v.assumptions)]
        found += [a for c in layout.constants for a in c.assumptions]
    return sorted(set(found), key=lambda a: (a.id.split("-")[0], int(a.id.split("-")[1])))


def _c_assumption_legend() -> list[str]:
    return [f" *   {a.id}: {a.summary}" for a in _all_assumptions()]


def _c_define(
    name: str, value: str, indent: bool = False, assumptions: Iterable[Assumption] = ()
) -> tuple[str, str, str]:
    return ("#define   " if indent else "#define ") + "SUPI3_" + name, value, _c_assumptions(assumptions)


def _c_line(line: tuple[str, str, str], width: int) -> str:
    macro, value, comment = line
    text = macro.ljust(width) + value
    return f"{macro.ljust(width)}{value.ljust(_C_VALUE_WIDTH)} {comment}" if comment else text


def _c_join(lines: list[_CLine]) -> str:
    width = max(len(line[0]) for line in lines if isinstance(line, tuple)) + 1
    return "\n".join(line if isinstance(line, str) else _c_line(line, width) for line in lines)


def _c_hex(value: int) -> str:
    return f"0x{value:02X}u"


def _c_fields(layout: ByteLayout) -> list[_CLine]:
    lines: list[_CLine] = []
    for f in layout.fields:
        lines += [
            _c_define(f"{layout.name}_{f.name}_POS", f"{f.lsb}u", True, f.assumptions),
            _c_define(f"{layout.name}_{f.name}_MSK", _c_hex(f.mask), True, f.assumptions),
        ]
        lines += [
            _c_define(f"{layout.name}_{f.name}_{v.name}", _c_hex(v.value << f.lsb), True, f.assumptions + v.assumptions)
            for v in f.values
        ]
    return lines


def _field_assumptions(layout: ByteLayout) -> list[Assumption]:
    """Every decision a layout's fields rest on, in field order (for macros built from the whole layout)."""
    return [a for f in layout.fields for a in f.assumptions]


def _c_command_macros() -> list[_CLine]:
    cmd = f"SUPI3_{REGISTER_MAP.command_byte.name}"
    assumed = _field_assumptions(REGISTER_MAP.command_byte)
    return [
        "",
        "/* Command byte for a read, a write, or (Motorola only) a simultaneous read and write of address addr. */",
        _c_define("CMD_A(addr)", f"(((addr) << {cmd}_A_POS) & {cmd}_A_MSK)", assumptions=assumed),
        _c_define("CMD_READ(addr)", f"({cmd}_RD_MSK | {cmd}_A(addr))", assumptions=assumed),
        _c_define("CMD_WRITE(addr)", f"({cmd}_WR_MSK | {cmd}_A(addr))", assumptions=assumed),
        _c_define("CMD_READ_WRITE(addr)", f"({cmd}_RD_MSK | {cmd}_WR_MSK | {cmd}_A(addr))", assumptions=assumed),
    ]


def to_c_header() -> str:
    """Return the firmware header ``supi3_regs.h`` (C99, no includes).

    Macros: ``SUPI3_<REG>_ADDR`` and ``SUPI3_<REG>_RESET`` per register (the write and the read register of an
    address each have their own), ``SUPI3_<REG>_<FIELD>_POS``/``_MSK`` indented under their register, field
    values in position as ``SUPI3_<REG>_<FIELD>_<VALUE>``, ``SUPI3_<REG>_CLEAR_ON_READ_MSK`` for read-clear
    registers, the command byte (``SUPI3_CMD_*``, ``SUPI3_CMD_WRITE(addr)``, ...) and the initialization byte
    (``SUPI3_INIT_*``). A macro whose value rests on recorded decisions (the ``assumptions`` of its field, value or
    constant) ends in a comment naming them, ``/* assumption RM-7 */``; the opening comment lists their summaries.
    """
    writes = {a: _port_summary(REGISTER_MAP.port(a, AccessDirection.WRITE)) for a in REGISTER_MAP.addresses}
    width = max(len(text) for text in writes.values()) + 2
    lines: list[_CLine] = [
        "/**",
        f" * {TITLE}: register addresses, field masks and interface bytes.",
        f" * Generated from {GENERATOR}. Do not edit.",
        f" * Source: {MANUAL}, 3.4.3 to 3.4.14.",
        " * Layout decisions for the manual's missing figures: docs/assumptions/regmap.md (RM-n; UP-n are in",
        " * docs/assumptions/upif.md). A macro that rests on one ends in a comment naming it (assumption RM-n):",
        *_c_assumption_legend(),
        " *",
        " * _ADDR is the address A3..0 for the command byte; where Table 3-10 names a different write and read",
        " * register at one address, each has its own _ADDR. _POS is a field's lowest bit, _MSK its mask in",
        " * position; field value macros are in position too. Accesses: r read, w write, rc read-clear.",
        " *",
        f" * Addr  {'Write'.ljust(width)}Read",
        *(
            f" * {a:4}  {writes[a].ljust(width)}{_port_summary(REGISTER_MAP.port(a, AccessDirection.READ))}"
            for a in REGISTER_MAP.addresses
        ),
        " */",
        "#ifndef SUPI3_REGS_H",
        "#define SUPI3_REGS_H",
        "",
        _c_define("ADDR_COUNT", f"{len(REGISTER_MAP.addresses)}u"),
        *(
            _c_define("BLOCK_TRANSFER_ADDR", _c_hex(p.address))
            for p in REGISTER_MAP.ports
            if p.access is Access.BLOCK_TRANSFER and p.direction is AccessDirection.WRITE
        ),
    ]
    for layout in _layouts():
        lines += ["", f"/* {layout.name}: {layout.title} ({layout.ref}). Not addressable. */", *_c_fields(layout)]
        lines += [
            _c_define(f"{layout.name}_{c.name}", _c_hex(c.value), assumptions=c.assumptions) for c in layout.constants
        ]
    lines += _c_command_macros()
    for register in REGISTER_MAP.registers:
        ports = ", ".join(f"{p.direction.value} ({p.access.value})" for p in _ports_of(register))
        assumed = _field_assumptions(register)  # the read-clear mask follows from the field layout
        lines += [
            "",
            f"/* {register.name}: {register.title}. Address {register.address}, {ports}.",
            f" * Ref: {register.ref}. Cleared by: {_resets(register)} reset. */",
            _c_define(f"{register.name}_ADDR", _c_hex(register.address)),
            _c_define(f"{register.name}_RESET", _c_hex(register.reset)),
        ]
        lines += [
            _c_define(f"{register.name}_CLEAR_ON_READ_MSK", _c_hex(p.clear_on_read_mask), False, assumed)
            for p in _ports_of(register)
            if p.clear_on_read_mask
        ]
        lines += _c_fields(register)
    text = _c_join([*lines, "", "#endif /* SUPI3_REGS_H */", ""])
    return text.replace("µ", "u")


# ----------------------------------------------------------------------------------------------------------------
# One entry point
# ----------------------------------------------------------------------------------------------------------------

_TEXT_FORMATS: Final[dict[str, Callable[[], str]]] = {
    "md": to_markdown,
    "rdl": to_systemrdl,
    "h": to_c_header,
    "json": to_json,
}


def render(fmt: str, out: Path | None = None) -> str:
    """Render the register map in format ``fmt`` and write it to ``out`` if given.

    Parameters
    ----------
    fmt:
        One of :data:`FORMATS`: ``html`` (a directory, ``out`` required), ``md``, ``rdl``, ``h``, ``json``.
    out:
        File to write (the directory for ``html``); ``None`` only returns the text.

    Returns
    -------
    str
        The rendered text; for ``html``, the path of the generated ``index.html``.

    Raises
    ------
    RegisterMapError
        If ``fmt`` is not a known format, ``out`` is neither a :class:`~pathlib.Path` nor ``None``, or ``html`` is
        asked for without ``out``.
    """
    if not isinstance(fmt, str):
        raise RegisterMapError(f"format must be one of {', '.join(FORMATS)}, not {fmt!r:.40}")
    if out is not None:
        _path("out", out)
    if fmt == "html":
        if out is None:
            raise RegisterMapError("format 'html' writes a directory: give an output path")
        return str(to_html(out))
    if fmt not in _TEXT_FORMATS:
        raise RegisterMapError(f"unknown register map format {fmt!r}; choose one of {', '.join(FORMATS)}")
    if out is not None and out.is_dir():  # else the write fails with Python's IsADirectoryError after the render
        raise RegisterMapError(f"format {fmt!r} writes a file: out {str(out)!r:.80} is a directory")
    text = _TEXT_FORMATS[fmt]()
    if out is not None:
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(text, encoding="utf-8")
    return text


def write_checked_in(root: Path) -> list[Path]:
    """Regenerate the checked-in files (:data:`CHECKED_IN`) under the repository ``root``; return their paths."""
    paths = [_path("root", root) / path for path in CHECKED_IN.values()]
    for fmt, path in zip(CHECKED_IN, paths, strict=True):
        render(fmt, path)
    return paths
