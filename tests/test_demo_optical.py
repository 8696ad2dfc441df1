"""``supi3 demo --optical`` (supi3.demo.run_optical) through the command line: a ring of SUPI 3 OPC chips joined by
fibre (manual 1.6) with a bus terminal module and a local bus (2.4), the master's optical diagnostic table (Figure
1-10), a bend of the branch path that online regulation compensates with MAU warnings the master reports (1.6.2,
1.6.3, OPT-52), a pulled local bus connector the master locates on its exact line (2.2.2, BK-7), and the plot of the
bent path."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from supi3 import demo
from supi3.cli import main
from supi3.errors import ArgumentError

SVG = "{http://www.w3.org/2000/svg}"


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, list[str], str]:
    code = main(["demo", "--optical", *argv])
    out, err = capsys.readouterr()
    return code, out.splitlines(), err


def _tables(lines: list[str]) -> list[list[list[str]]]:
    """The rows of every diagnostic table printed, in order, as cells."""
    tables: list[list[list[str]]] = []
    for i, line in enumerate(lines):
        if line.split()[:2] == ["Path", "Forward"]:
            rows = []
            for row in lines[i + 1 :]:
                if not re.match(r"  \d+\.\d<->", row):
                    break
                rows.append(re.split(r"\s{2,}", row.strip()))
            tables.append(rows)
    return tables


@pytest.mark.parametrize("bit_rate", ["500k", "2M"])
def test_demo_story(capsys: pytest.CaptureFixture[str], tmp_path: Path, bit_rate: str) -> None:
    plot = tmp_path / "levels.html"
    code, lines, err = _run(capsys, "--bit-rate", bit_rate, "--plot", str(plot))
    assert code == 0 and not err
    assert "a bus terminal module (3.0, BK-LBD) with a local bus of 3 LBD-MR devices" in lines[0]
    assert "discovery ID cycle: ok" in lines[2]
    first, last = _tables(lines)
    assert [row[0] for row in first] == ["1.0<->2.0", "2.0<->3.0", "3.0<->3.1", "3.1<->3.2", "3.2<->3.3",
                                         "3.0<->4.0", "4.0<->5.0"]  # fmt: skip
    assert all(row[1] == row[2] == "optimal" and row[3].endswith("(of 15)") for row in first)
    assert first[5][-1] == "glass" and first[1][-1] == "polymer"  # HCS reports polymer (OPT-3)
    # after the repair the master restarted the bus: the same paths, lengths and media, levels within one
    assert [(r[0], r[1], r[2], r[5], r[6]) for r in last] == [(r[0], r[1], r[2], r[5], r[6]) for r in first]
    assert all(abs(int(a[3].split()[0]) - int(b[3].split()[0])) <= 1 for a, b in zip(first, last, strict=True))
    events = [line.split("ms  ", 1)[1] for line in lines if re.match(r" +\d+\.\d{3} ms  ", line)]
    assert events[:4] == ["MAU warning on  at 3.1 incoming interface (MAUWH, 0BD4h)",
                          "MAU warning on  at 3.0 branch interface (MAUWS, 0BD4h)",
                          "MAU warning off at 3.1 incoming interface (MAUWH, 0BD4h)",
                          "MAU warning off at 3.0 branch interface (MAUWS, 0BD4h)"]  # fmt: skip
    # the pulled connector of 3.2<->3.3, located on its exact line by the counter telegram (BK-7)
    assert events[4] == ("cycle failed: dead line at 3.2 (line 5), by the counter telegram: BK 3.0 counted 2 "
                         "(LBD-MR): the return line into device 2")
    failures = [e for e in events if e.startswith("cycle failed")]
    assert all(e == events[4] or e.endswith("not located") for e in failures)  # never a wrong position
    assert events[-1].startswith("the ring runs again: Alarm Stop, optical initialization and discovery ID cycle: ok")
    assert lines[-1] == f"wrote {plot}"
    _check_plot(plot)


def _check_plot(plot: Path) -> None:
    html = plot.read_text(encoding="utf-8")
    assert html.startswith("<!DOCTYPE html>") and "<script" not in html and "http://" not in html.replace(
        'xmlns="http://www.w3.org/2000/svg"', "")  # self-contained
    svg = ET.fromstring(html[html.index("<svg") : html.index("</svg>") + 6])
    lines = svg.findall(f"{SVG}polyline")
    assert [line.findtext(f"{SVG}title") for line in lines] == ["forward", "return"]
    bands = [rect.findtext(f"{SVG}title") for rect in svg.findall(f"{SVG}rect")]
    assert bands == ["bend", "3.2<->3.3 pulled"]
    ys = {float(p.split(",")[1]) for p in lines[0].attrib["points"].split()}
    top = min(float(t.attrib["y"]) for t in svg.findall(f"{SVG}text") if t.text == "15") - 4
    assert top in ys  # the bend drove the forward transmitter to level 15


def test_demo_cycles_and_errors(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    code, lines, _ = _run(capsys, "--cycles", "20")
    assert code == 0 and not any("MAU" in line for line in lines)  # over before the bend
    assert _tables(lines)[0] == _tables(lines)[1]
    for argv, message in ((["--vcd", str(tmp_path / "x.vcd")], "neither --analog nor --vcd"),
                          (["--analog"], "neither --analog nor --vcd"), (["--cycles", "0"], "--cycles must be"),
                          (["--plot", str(tmp_path)], "is a directory")):  # fmt: skip
        code, _, err = _run(capsys, *argv)
        assert code == 2 and message in err
    assert main(["demo", "--plot", str(tmp_path / "p.html")]) == 2
    assert "--plot is for demo --optical only" in capsys.readouterr().err
    with pytest.raises(ArgumentError, match=r"^cycles must be"):
        list(demo.run_optical(0))


def test_plot_write_error(tmp_path: Path) -> None:
    with pytest.raises(demo.DemoError, match="--plot"):
        list(demo.run_optical(4, tmp_path / "missing" / "plot.html"))
