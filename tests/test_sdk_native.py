"""supi3.sdk.native: building C firmware with cffi, the board contract, and errors raised in callbacks.

The firmware here are small C files written into the test's folder; the shipped examples are tested in
tests/test_sdk_c_examples.py.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from supi3.config import decode
from supi3.errors import ArgumentError
from supi3.model.registers import ReconfigurationError, RegisterFile
from supi3.regmap import REGISTER_MAP, AccessDirection, decode_command
from supi3.sdk import native
from supi3.sdk.bench import Bench
from supi3.sdk.driver import Supi3Driver, Transport
from supi3.sdk.native import CFirmware, CFirmwareError, CompilerNotFoundError, NativeBuildError
from supi3.sdk.transports import ModelTransport
from support import TEST_FIRMWARE, c_firmware

SETUP_ONLY = """
#include "fw_board.h"
void fw_setup(supi3_t *chip, fw_board_t *board)
{
    (void)fw_note(board, supi3_initialize(chip, SUPI3_MODE_MOTOROLA));
}
"""

ISR_ONLY = """
#include "fw_board.h"
void fw_isr(supi3_t *chip, fw_board_t *board) { (void)chip, (void)board; }
"""


@pytest.fixture
def cache(pytestconfig: pytest.Config) -> pytest.Cache:
    assert pytestconfig.cache is not None
    return pytestconfig.cache


def _firmware(cache: pytest.Cache, folder: Path, text: str, name: str = "fw.c") -> CFirmware:
    source = folder / name
    source.write_text(text)
    return c_firmware(cache, source)


def _regs_driver() -> Supi3Driver:
    return Supi3Driver(ModelTransport(RegisterFile(decode("10011", "1110"))))  # RB, Init-µP (Table 2-4)


# -- describe_command: every command byte in the manual's words (3.4.4, Table 3-10) ----------------------------------


@pytest.mark.parametrize("byte", range(256))
def test_describe_command_names_the_access_of_every_byte(byte: int) -> None:
    text = native.describe_command(byte)
    if byte & 0x30:
        assert text == f"byte {byte:02X}h (not a command: reserved bits set)"
        return
    command = decode_command(byte)
    assert text.startswith(f"command {byte:02X}h (")
    if command.block_transfer:
        assert text.endswith("(block transfer)")
        return
    for flag, direction in ((command.rd, AccessDirection.READ), (command.wr, AccessDirection.WRITE)):
        register = REGISTER_MAP.port(command.address, direction).register
        if flag:
            assert f"{direction.value} {register.name if register else 'nothing'}" in text
    if not (command.rd or command.wr):
        assert text.endswith(f"(no access, address {command.address})")


def test_describe_command_examples() -> None:
    assert native.describe_command(0x81) == "command 81h (read OUT1)"
    assert native.describe_command(0x4D) == "command 4Dh (write SET)"
    assert native.describe_command(0xC0) == "command C0h (read OUT0, write IN0)"
    assert native.describe_command(0x8F) == "command 8Fh (block transfer)"


# -- finding the toolchain and building --------------------------------------------------------------------------------


def test_no_compiler_is_a_named_error(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CC", "no-such-compiler-supi3")
    with pytest.raises(CompilerNotFoundError, match="no C compiler found: tried no-such-compiler-supi3"):
        native.find_compiler()
    monkeypatch.delenv("CC")
    monkeypatch.setenv("PATH", "")
    with pytest.raises(CompilerNotFoundError, match="tried cc, gcc, clang"):
        native.find_compiler()
    assert native.toolchain_missing() is not None


def test_build_refuses_what_is_not_a_c_file(tmp_path: Path) -> None:
    header = tmp_path / "x.h"
    header.write_text("")
    for bad in (tmp_path / "missing.c", header, 3):
        with pytest.raises(ArgumentError, match=r"sources must be paths of existing \.c files"):
            native.build([bad], cache_dir=tmp_path)  # type: ignore[list-item]
    with pytest.raises(ArgumentError, match=r"name must be an example firmware \(analog_io, "):
        native.example("nope")
    source = tmp_path / "fw.c"
    source.write_text(SETUP_ONLY)
    for defines in ({"1X": "1"}, {"X": 1}, ["X"]):
        with pytest.raises(ArgumentError, match="defines must"):
            native.build(source, defines=defines, cache_dir=tmp_path)  # type: ignore[arg-type]


def test_warnings_are_errors(cache: pytest.Cache, tmp_path: Path) -> None:
    text = SETUP_ONLY.replace("{\n", "{\n    int unused;\n", 1)
    with pytest.raises(NativeBuildError, match=r"(?s)fw.c does not compile with -std=c99 .*-Werror.*unused"):
        _firmware(cache, tmp_path, text)


def test_fw_setup_is_required(cache: pytest.Cache, tmp_path: Path) -> None:
    with pytest.raises(NativeBuildError, match=r"must define fw_setup"):
        _firmware(cache, tmp_path, ISR_ONLY)


def test_the_build_is_cached_by_content(cache: pytest.Cache, tmp_path: Path) -> None:
    """NC-8: the same sources (wherever they are) are one build; a change is another."""
    if (reason := native.toolchain_missing()) is not None:
        pytest.skip(reason)
    folder = cache.mkdir("supi3-native")
    first, second = tmp_path / "a" / "fw.c", tmp_path / "b" / "fw.c"
    for source in (first, second):
        source.parent.mkdir()
        source.write_text(SETUP_ONLY)
    built = native.build(first, cache_dir=folder)
    assert built.path.parent == folder and built.path.is_file()
    assert native.build(second, cache_dir=folder).path == built.path
    (second.parent / "local.h").write_text("/* a header beside the source counts */\n")
    assert native.build(second, cache_dir=folder).path != built.path
    first.write_text(SETUP_ONLY + "/* changed */\n")
    assert native.build(first, cache_dir=folder).path != built.path


def test_entry_points_decide_the_firmware_class(cache: pytest.Cache) -> None:
    """fw_loop makes a main loop (the bench runs one only then); fw_isr is optional too (fw_board.h)."""
    looping = c_firmware(cache, native.example("polling_io"))
    interrupt_only = c_firmware(cache, native.example("digital_io"))
    assert isinstance(looping, CFirmware) and isinstance(interrupt_only, CFirmware)
    assert (looping.library.has_isr, looping.library.has_loop) == (False, True)
    assert (interrupt_only.library.has_isr, interrupt_only.library.has_loop) == (True, False)
    assert type(looping).loop is not type(interrupt_only).loop


def test_each_firmware_has_its_own_static_variables(cache: pytest.Cache, tmp_path: Path) -> None:
    """Two CFirmware of one source are two boards: statics start at zero in each (private library copies)."""
    text = SETUP_ONLY + """
void fw_loop(supi3_t *chip, fw_board_t *board)
{
    static uint32_t passes = 0u;
    (void)chip;
    board->cycles = ++passes;
}
"""
    first, second = _firmware(cache, tmp_path, text), _firmware(cache, tmp_path, text)
    for firmware in (first, second):
        firmware.setup(_regs_driver())
    for _ in range(3):
        first.call("fw_loop")
    second.call("fw_loop")
    assert (first.board.cycles, second.board.cycles) == (3, 1)


# -- the board contract ----------------------------------------------------------------------------------------------


def test_c_firmware_runs_on_a_bare_model_transport(cache: pytest.Cache, tmp_path: Path) -> None:
    """Any Transport will do; /StatErr and /ModAck are the bench's, so elsewhere they answer 'not wired' (-6)."""
    text = SETUP_ONLY + """
void fw_loop(supi3_t *chip, fw_board_t *board)
{
    int seen = 0;
    board->outputs[0] = (uint8_t)-board->set_stat_err(board->user, 1);
    board->outputs[1] = (uint8_t)-board->mod_ack_seen(board->user, &seen);
    (void)fw_note(board, supi3_write(chip, SUPI3_IN0_ADDR, board->inputs[0]));
}
"""
    firmware = _firmware(cache, tmp_path, text)
    driver = _regs_driver()
    firmware.setup(driver)
    firmware.board.inputs[0] = 0x5A
    firmware.call("fw_loop")
    assert bytes(firmware.board.outputs[0:2]) == bytes([6, 6])
    assert isinstance(driver.transport, ModelTransport)
    assert driver.transport.registers.value("IN0") == 0x5A


def test_driver_errors_the_firmware_keeps_raise_cfirmware_error(cache: pytest.Cache, tmp_path: Path) -> None:
    text = """
#include "fw_board.h"
void fw_setup(supi3_t *chip, fw_board_t *board)
{
    uint8_t value = 0u;
    (void)fw_note(board, supi3_read(chip, SUPI3_OUT0_ADDR, &value)); /* before supi3_initialize */
}
"""
    firmware = _firmware(cache, tmp_path, text)
    with pytest.raises(CFirmwareError, match=r"fw_setup\(\) reported driver error -2: not initialized"):
        firmware.setup(_regs_driver())


def test_call_checks_its_entry_point_and_attachment(cache: pytest.Cache, tmp_path: Path) -> None:
    firmware = _firmware(cache, tmp_path, SETUP_ONLY)
    with pytest.raises(CFirmwareError, match=r"fw_setup\(\) before setup\(\)"):
        firmware.call("fw_setup")
    with pytest.raises(ArgumentError, match=r"entry must be one of the firmware's entry points \(fw_setup\)"):
        firmware.call("fw_loop")
    with pytest.raises(ArgumentError, match=r"transport must be a supi3\.sdk\.driver\.Transport"):
        firmware.attach(object())  # type: ignore[arg-type]
    with pytest.raises(ArgumentError, match=r"frame_gap_us must be an integer from 0 to"):
        c_firmware(cache, tmp_path / "fw.c", frame_gap_us=-1)


# -- exceptions in callbacks: raised again after the entry point, with a note ------------------------------------------


class _Exploding(ModelTransport):
    """The model, whose xfer raises ``error`` after ``after`` bytes."""

    def __init__(self, error: BaseException, after: int) -> None:
        super().__init__(RegisterFile(decode("10011", "1110")))
        self.error = error
        self.after = after
        self.sent: list[int] = []

    def xfer(self, tx: int, s_r: bool) -> int:
        if len(self.sent) == self.after:
            raise self.error
        self.sent.append(tx)
        return super().xfer(tx, s_r)


@pytest.mark.parametrize("error", [KeyError("boom"), ZeroDivisionError("x"), KeyboardInterrupt()])
def test_a_callback_exception_is_raised_again_unchanged(cache: pytest.Cache, tmp_path: Path,
                                                        capfd: pytest.CaptureFixture[str],
                                                        error: BaseException) -> None:  # fmt: skip
    """Same object, type and message; later callbacks fail at once (nothing more is sent); nothing printed."""
    text = SETUP_ONLY.replace("}\n", """    (void)fw_note(board, supi3_write(chip, SUPI3_IN0_ADDR, 1u));
    (void)fw_note(board, supi3_write(chip, SUPI3_IN1_ADDR, 2u));
}
""")
    firmware = _firmware(cache, tmp_path, text)
    transport = _Exploding(error, after=2)  # init byte, command of the first write, then its data byte raises
    with pytest.raises(type(error)) as caught:
        firmware.setup(Supi3Driver(transport))
    assert caught.value is error
    assert caught.value.__notes__ == ["in fw_setup(): command 40h (write IN0), data byte (sent 01h)"]
    assert transport.sent == [0x00, 0x40]
    assert capfd.readouterr() == ("", "")
    transport.after = 99  # the firmware works again after the error was raised (once the chip is reset)
    transport.set_sas_init(1)
    firmware.call("fw_setup")
    assert transport.sent[2:] == [0x00, 0x40, 0x01, 0x41, 0x02]
    assert transport.registers.value("IN1") == 0x02


def test_a_plain_transport_error_names_the_byte(cache: pytest.Cache, tmp_path: Path) -> None:
    """Without the model's protocol state the note can only name the byte."""

    class Broken(Transport):
        def xfer(self, tx: int, s_r: bool) -> int:
            raise OSError(f"SPI controller gone ({tx:02X}h, S/R {s_r:d})")

    firmware = _firmware(cache, tmp_path, SETUP_ONLY)
    with pytest.raises(OSError, match=r"SPI controller gone \(00h, S/R 1\)") as caught:
        firmware.setup(Supi3Driver(Broken()))
    assert caught.value.__notes__ == ["in fw_setup(): byte 00h"]


def test_reconfiguration_in_the_isr_reaches_pytest_as_such(cache: pytest.Cache,
                                                            capfd: pytest.CaptureFixture[str]) -> None:  # fmt: skip
    """tests/c/firmware/reconfigure_bug.c writes SET in its VALID service routine while the bus runs (3.4.3,
    3.4.11): the strict model's ReconfigurationError comes out of bench.run() with the firmware's context."""
    firmware = c_firmware(cache, TEST_FIRMWARE / "reconfigure_bug.c")
    bench = Bench(firmware=firmware)
    with pytest.raises(ReconfigurationError, match=r"SET written with 85h during bus operation \(3.4.3, 3.4.11\)") \
            as caught:  # fmt: skip
        bench.run(10)
    assert caught.value.__notes__ == ["in fw_isr(): command 4Dh (write SET), data byte (sent 85h)"]
    out, err = capfd.readouterr()
    assert "Exception ignored" not in out + err and "From cffi callback" not in out + err
    assert (out, err) == ("", "")
    assert sys.exc_info() == (None, None, None)


def test_an_error_in_a_pin_read_names_the_pin(cache: pytest.Cache, tmp_path: Path) -> None:
    class BadIrq(ModelTransport):
        broken = False

        def read_irq(self) -> int:
            if self.broken:
                raise RuntimeError("pin broken")
            return super().read_irq()

    text = SETUP_ONLY + """
void fw_isr(supi3_t *chip, fw_board_t *board)
{
    uint8_t events = 0u;
    (void)fw_note(board, supi3_irq_service(chip, &events));
}
"""
    firmware = _firmware(cache, tmp_path, text)
    transport = BadIrq(RegisterFile(decode("10011", "1110")))
    firmware.setup(Supi3Driver(transport))
    transport.broken = True
    with pytest.raises(RuntimeError, match="pin broken") as caught:
        firmware.call("fw_isr")
    assert caught.value.__notes__ == ["in fw_isr(): reading /IRQ (read_irq)"]

