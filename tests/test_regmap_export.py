"""Exporters: SystemRDL compiles and agrees with the declaration; HTML, JSON, Markdown and render() behave."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from supi3.errors import Supi3Error
from supi3.regmap import CHECKED_IN, FORMATS, REGISTER_MAP, AccessDirection, RegisterMapError, render, to_systemrdl
from supi3.regmap.__main__ import main
from supi3.regmap.export import compile_systemrdl


@pytest.fixture(scope="module")
def rdl_top() -> Any:
    return compile_systemrdl(to_systemrdl())


def test_systemrdl_compiles_and_agrees_with_the_declaration(rdl_top: Any) -> None:
    from systemrdl.node import RegNode

    registers = {node.inst_name: node for node in rdl_top.children() if isinstance(node, RegNode)}
    assert set(registers) == {r.name for r in REGISTER_MAP.registers}
    for register in REGISTER_MAP.registers:
        node = registers[register.name]
        assert node.raw_address_offset == register.address and node.get_property("regwidth") == 8
        directions = {p.direction for p in REGISTER_MAP.ports if p.register is register}
        assert node.has_sw_writable == (AccessDirection.WRITE in directions)
        assert node.has_sw_readable == (AccessDirection.READ in directions)
        fields = {f.inst_name: f for f in node.fields()}
        assert set(fields) == {f.name for f in register.base_fields}
        for field in register.base_fields:
            assert (fields[field.name].low, fields[field.name].high) == (field.lsb, field.msb)
            assert fields[field.name].get_property("reset") == field.extract(register.reset)


def test_systemrdl_read_clear_only_on_events(rdl_top: Any) -> None:
    from systemrdl.node import FieldNode
    from systemrdl.rdltypes.builtin_enums import OnReadType

    cleared = {
        (f.parent.inst_name, f.inst_name)
        for f in rdl_top.descendants()
        if isinstance(f, FieldNode) and f.get_property("onread") is OnReadType.rclr
    }
    events = {
        (p.register.name, f.name)
        for p in REGISTER_MAP.ports
        if p.register is not None
        for f in p.register.base_fields
        if p.clear_on_read_mask & f.mask
    }
    assert cleared == events and len(events) == 7


def test_systemrdl_rejection_is_a_register_map_error() -> None:
    with pytest.raises(RegisterMapError, match="rejected"):
        compile_systemrdl("addrmap broken {")


def test_html_is_a_browsable_site(tmp_path: Path) -> None:
    index = Path(render("html", tmp_path / "html"))
    assert index == tmp_path / "html" / "index.html" and index.exists()
    pages = "".join(p.read_text(encoding="utf-8") for p in (tmp_path / "html" / "content").glob("*.html"))
    assert "Interrupt event" in pages and "Block transfer" in pages


def test_json_mirrors_the_declaration() -> None:
    document = json.loads(render("json"))
    assert len(document["ports"]) == 32 and document["address_bits"] == 4
    assert [r["name"] for r in document["registers"]] == [r.name for r in REGISTER_MAP.registers]
    set_register = next(r for r in document["registers"] if r["name"] == "SET")
    assert set_register["reset"] == 0 and set_register["cleared_by"] == ["power-up"]
    assert {c["name"]: c["value"] for b in document["interface_bytes"] for c in b["constants"]} == {
        "BLOCK_TRANSFER": 0xCF,
        "MOTOROLA": 0x00,
        "INTEL": 0x81,
    }


def test_markdown_lists_every_address_and_register() -> None:
    text = render("md")
    for address in REGISTER_MAP.addresses:
        assert f"| {address} ({address:02X}h) |" in text
    for register in REGISTER_MAP.registers:
        assert f"### {register.name}\n" in text


@pytest.mark.parametrize("fmt", [f for f in FORMATS if f != "html"])
def test_render_writes_what_it_returns(tmp_path: Path, fmt: str) -> None:
    out = tmp_path / "sub" / f"regmap.{fmt}"
    assert render(fmt, out) == out.read_text(encoding="utf-8")


def test_render_rejects_bad_requests() -> None:
    with pytest.raises(Supi3Error, match="unknown register map format 'pdf'; choose one of html, md"):
        render("pdf")
    with pytest.raises(RegisterMapError, match="give an output path"):
        render("html")


def test_write_checked_in(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["--write-checked-in", "--root", str(tmp_path)]) == 0
    printed = capsys.readouterr().out.splitlines()
    assert printed == [str(tmp_path / path) for path in CHECKED_IN.values()]
    for fmt, path in CHECKED_IN.items():
        assert (tmp_path / path).read_text(encoding="utf-8") == render(fmt)
