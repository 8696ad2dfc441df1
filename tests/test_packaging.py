"""What an installed supi3 does without the source tree and without its optional extras.

* The software SPI master (``supi3.spi.master.SoftMaster``) imports and drives the pin model with every optional
  extra blocked (a meta-path hook refuses wavedrom, Amaranth, cocotb, the SystemRDL tools, ...), and ``supi3
  figures`` then stops with one error line, status 2 and nothing written.
* A wheel built from the tree and installed outside it runs the per-cycle (cocotb) and the batch lockstep of the
  example design, importing nothing from the tree, in this process or in the simulator's (slow).
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import tomllib
import zipfile
from email.parser import Parser
from pathlib import Path

import pytest

import supi3
from supi3.cli import main

ROOT = Path(__file__).resolve().parents[1]
PACKAGE_PARENT = Path(supi3.__file__).resolve().parents[1]
"""The folder the tests import supi3 from (``src`` of the tree under test)."""

EXTRAS = ("wavedrom", "systemrdl", "peakrdl_html", "peakrdl_markdown", "peakrdl_cheader", "amaranth", "cocotb",
          "cocotb_tools", "cocotbext", "verilator", "pytest", "hypothesis")
"""Top-level modules of the optional extras (docs, rtl, test): the base install has only numpy and pyvcd."""

_BLOCKER = """\
import sys

BLOCKED = set({blocked!r})


class Blocker:
    \"\"\"Refuses the optional extras' modules, as if they were not installed.\"\"\"

    def find_spec(self, name, path=None, target=None):
        if name.partition(".")[0] in BLOCKED:
            raise ModuleNotFoundError(f"No module named {{name!r}} (blocked by the test)", name=name)
        return None


sys.meta_path.insert(0, Blocker())
"""

_BASE_INSTALL_SCRIPT = """\
import io
import json
import sys
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

try:
    import wavedrom
except ModuleNotFoundError:
    pass
else:
    raise AssertionError("the blocker let wavedrom through")

from supi3.config import decode
from supi3.model.registers import RegisterFile
from supi3.regmap import IN0, SET, encode_command
from supi3.spi.master import SoftMaster, decode_bytes
from supi3.spi.slave_pins import SlavePins
from supi3.spi.upif import Mode

chip = SlavePins(RegisterFile(decode("10011", "1110")))
master = SoftMaster(chip, Mode.MOTOROLA)
master.byte(Mode.MOTOROLA.init_byte)
master.byte(encode_command(SET.address, wr=True))
master.byte(0x82)
master.deselect()  # /SS rises: the chip takes the SET byte
chip.registers.latch(b"\\x3c")
master.byte(encode_command(IN0.address, rd=True, wr=True))
received = master.byte(0x11)
master.deselect()

from supi3.spi.figures import FIGURES, to_wavejson  # the scenarios and WaveJSON need no wavedrom either

wavejson = to_wavejson(FIGURES[0].build(), "no wavedrom")
from supi3.cli import main

out, err = io.StringIO(), io.StringIO()
with redirect_stdout(out), redirect_stderr(err):
    status = main(["figures", "-o", sys.argv[1]])
print(json.dumps({
    "received": received,
    "set": chip.registers.value("SET"),
    "in0": chip.registers.value("IN0"),
    "frames": [(f.to_chip, f.from_chip) for f in decode_bytes(master.trace())],
    "lanes": len(wavejson["signal"]),
    "status": status,
    "stdout": out.getvalue(),
    "stderr": err.getvalue(),
    "extras": sorted(name for name in sys.modules if name.partition(".")[0] in BLOCKED),
}))
"""


def _python(script: Path, *args: str, cwd: Path, pythonpath: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, "PYTHONPATH": str(pythonpath)}
    return subprocess.run([sys.executable, str(script), *args], cwd=cwd, env=env, capture_output=True, text=True,
                          check=False)


def _name(requirement: str) -> str:
    match = re.match(r"[A-Za-z0-9_.-]+", requirement)
    assert match is not None, requirement
    return match.group(0).lower()


def test_the_base_install_is_numpy_and_pyvcd() -> None:
    """What the blocked-extras test leaves importable is what ``pip install supi3`` installs."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    assert sorted(map(_name, project["dependencies"])) == ["numpy", "pyvcd"]


def test_soft_master_works_without_any_extra(tmp_path: Path) -> None:
    """``from supi3.spi.master import SoftMaster`` on the base install: a register write, a full-duplex byte."""
    script = tmp_path / "base_install.py"
    script.write_text(_BLOCKER.format(blocked=sorted(EXTRAS)) + _BASE_INSTALL_SCRIPT, encoding="utf-8")
    figures = tmp_path / "figures"
    result = _python(script, str(figures), cwd=tmp_path, pythonpath=PACKAGE_PARENT)
    assert result.returncode == 0, result.stderr[-3000:]
    report = json.loads(result.stdout)
    assert report["received"] == 0x3C and report["set"] == 0x82 and report["in0"] == 0x11
    assert report["frames"][-1] == [0x11, 0x3C]
    assert report["lanes"] == 7
    assert report["extras"] == []
    # supi3 figures without the docs extra: one line, status 2, nothing written
    assert report["status"] == 2 and report["stdout"] == ""
    assert report["stderr"].count("\n") == 1 and "supi3[docs]" in report["stderr"], report["stderr"]
    assert "Traceback" not in report["stderr"]
    assert not figures.exists()


def test_figures_command_checks_its_folder_first(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    regular = tmp_path / "regular.txt"
    regular.write_text("not a folder\n", encoding="utf-8")
    for target, reason in ((regular, "not a directory"), (tmp_path / "missing" / "figures", "does not exist")):
        assert main(["figures", "-o", str(target)]) == 2
        out, err = capsys.readouterr()
        assert out == "" and err.count("\n") == 1 and reason in err and "-o/--output" in err, err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["regular.txt"]


def test_figures_command_without_the_docs_extra(capsys: pytest.CaptureFixture[str], tmp_path: Path,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "wavedrom", None)  # as on `pip install supi3`: import fails
    assert main(["figures", "-o", str(tmp_path / "figures")]) == 2
    out, err = capsys.readouterr()
    assert out == "" and err.count("\n") == 1 and "supi3[docs]" in err and "wavedrom" in err, err
    assert list(tmp_path.iterdir()) == []


# The installed wheel -----------------------------------------------------------------------------------------------

_CHECKER = """\
\"\"\"The model factory of the wheel test: the example model, and a report of where supi3 came from.\"\"\"

import json
import os
import sys

from supi3.verif.example import ShiftCounterModel


def model() -> ShiftCounterModel:
    modules = {name: getattr(module, "__file__", None) for name, module in list(sys.modules.items())}
    with open(os.environ["SUPI3_WHEEL_REPORT"], "a", encoding="utf-8") as stream:
        stream.write(json.dumps({"pid": os.getpid(), "modules": modules}) + "\\n")
    return ShiftCounterModel()
"""

_WHEEL_SCRIPT = """\
import json
import sys
from pathlib import Path

import numpy as np

import supi3
from supi3.verif import Lockstep
from supi3.verif.example import ShiftCounter

import checker

rng = np.random.default_rng(3)
stimulus = rng.integers(0, 2, (3000, 5))
stimulus[:, 2] = rng.integers(0, 256, 3000)
bench = Lockstep(ShiftCounter, checker.model, build_dir=Path(sys.argv[1]))
results = [bench.run(stimulus), bench.run_batch(stimulus)]
print(json.dumps({
    "supi3": supi3.__file__,
    "results": [[result.path, result.simulator, result.cycles] for result in results],
}))
"""


def _copy_tree(target: Path) -> Path:
    """What a wheel is built from (pyproject.toml, README.md, src/), copied so that the build writes nothing into
    the tree."""
    target.mkdir()
    for name in ("pyproject.toml", "README.md"):
        shutil.copy2(ROOT / name, target / name)
    shutil.copytree(ROOT / "src", target / "src", ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
    return target


def _pip(*args: str | Path) -> None:
    result = subprocess.run([sys.executable, "-m", "pip", "--disable-pip-version-check", *map(str, args)],
                            capture_output=True, text=True, check=False)
    assert result.returncode == 0, (result.stdout + result.stderr)[-3000:]


@pytest.mark.rtl
@pytest.mark.slow
def test_installed_wheel_runs_both_lockstep_paths(tmp_path: Path) -> None:
    """Build the wheel, install it (without dependencies: this environment has them) into a folder outside the tree,
    and run the per-cycle and the batch lockstep of the example design from there, with the tree off the path."""
    from supi3.verif.errors import SimulatorUnavailableError
    from supi3.verif.rtl import ensure_toolchain

    try:
        ensure_toolchain("verilator")
    except SimulatorUnavailableError as error:
        pytest.skip(str(error))
    dist, site, work = tmp_path / "dist", tmp_path / "site", tmp_path / "work"
    _pip("wheel", "--no-deps", "--quiet", "-w", dist, _copy_tree(tmp_path / "tree"))
    [wheel] = dist.glob("supi3-*.whl")
    with zipfile.ZipFile(wheel) as archive:
        names = set(archive.namelist())
        [metadata] = [name for name in names if name.endswith(".dist-info/METADATA")]
        requires = Parser().parsestr(archive.read(metadata).decode("utf-8")).get_all("Requires-Dist") or []
    assert sorted(_name(r) for r in requires if ";" not in r) == ["numpy", "pyvcd"]
    assert {"amaranth", "cocotb", "verilator"} <= {_name(r) for r in requires if 'extra == "rtl"' in r}
    assert {"supi3/verif/testbenches/lockstep_tb.py", "supi3/verif/example.py", "supi3/py.typed"} <= names
    assert not any(name.startswith(("sim/", "tests/")) for name in names)
    _pip("install", "--no-deps", "--quiet", "--target", site, wheel)

    work.mkdir()
    (work / "checker.py").write_text(_CHECKER, encoding="utf-8")
    (work / "run_lockstep.py").write_text(_WHEEL_SCRIPT, encoding="utf-8")
    report = work / "report.jsonl"
    env = {**os.environ, "PYTHONPATH": str(site), "SUPI3_WHEEL_REPORT": str(report)}
    result = subprocess.run([sys.executable, "run_lockstep.py", str(tmp_path / "build")], cwd=work, env=env,
                            capture_output=True, text=True, check=False)
    assert result.returncode == 0, result.stderr[-3000:]
    outcome = json.loads(result.stdout.splitlines()[-1])
    assert Path(outcome["supi3"]).is_relative_to(site)
    assert outcome["results"] == [["per-cycle", "verilator", 3000], ["batch", "verilator", 3000]]

    processes = [json.loads(line) for line in report.read_text(encoding="utf-8").splitlines()]
    simulator = [p for p in processes if "supi3.verif.testbenches.lockstep_tb" in p["modules"]]
    assert len({p["pid"] for p in processes}) >= 2 and simulator, "the model ran in the simulator process too"
    # The environment may live inside the tree (CI's .ci/run makes .venv there): only its own files are allowed.
    environment = Path(sys.prefix).resolve()
    for process in processes:
        files = [Path(file).resolve() for file in process["modules"].values() if file]
        from_tree = [f for f in files if f.is_relative_to(ROOT) and not f.is_relative_to(environment)]
        assert not from_tree, "nothing is imported from the tree"
        supi3_files = [Path(file) for name, file in process["modules"].items() if name.partition(".")[0] == "supi3"]
        assert supi3_files and all(file.resolve().is_relative_to(site.resolve()) for file in supi3_files)
