"""The C driver (src/supi3/sdk/c) against the Python reference model: its bytes go through ``UpInterface.transfer``.

The driver is built as a shared library and loaded with ctypes; ``xfer`` is one ``transfer`` (S/R = ``s_r`` in
Intel mode), ``read_cd`` the protocol's C/D, ``read_irq`` the register file's /IRQ, ``set_sas_init`` its SAS_INIT.
The model runs in strict mode: any rule of 3.4 the driver broke would be raised (and fail the test).
"""

from __future__ import annotations

import ctypes
import shutil
import subprocess

import pytest

from supi3 import sdk
from supi3.config import decode
from supi3.model.registers import RegisterFile
from supi3.regmap import BLOCK_ADDRESS
from supi3.spi.upif import Mode, UpInterface

XFER = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_uint8, ctypes.POINTER(ctypes.c_uint8), ctypes.c_int)
DELAY = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.c_uint32)
READ_PIN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.POINTER(ctypes.c_int))
WRITE_PIN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_int)

OK, E_NOT_RESET = 0, -5
MOTOROLA, INTEL = 0, 1
SET_ADDR, ID_ADDR, IRQ_EN_ADDR = 13, 12, 14


class Config(ctypes.Structure):
    """``supi3_config_t``."""

    _fields_ = [
        ("xfer", XFER),
        ("delay_us", DELAY),
        ("read_irq", READ_PIN),
        ("read_cd", READ_PIN),
        ("set_sas_init", WRITE_PIN),
        ("user", ctypes.c_void_p),
        ("frame_gap_us", ctypes.c_uint32),
    ]


@pytest.fixture(scope="module")
def lib(tmp_path_factory: pytest.TempPathFactory) -> ctypes.CDLL:
    gcc = shutil.which("gcc")
    if gcc is None:
        pytest.skip("gcc not found: the C driver tests need it")
    out = tmp_path_factory.mktemp("sdk") / "libsupi3.so"
    build = subprocess.run(
        [gcc, "-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-shared", "-fPIC",
         f"-I{sdk.include_dir()}", *map(str, sdk.sources()), "-o", str(out)],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert build.returncode == 0, build.stderr
    return ctypes.CDLL(str(out))


class Board:
    """A model chip behind the driver's callbacks; exceptions raised in a callback are kept and re-raised."""

    def __init__(self, lib: ctypes.CDLL) -> None:
        self.lib = lib
        self.regs = RegisterFile(decode("10011", "1110"))  # RB, Init-µP
        self.up = UpInterface(self.regs)
        self.mode: Mode | None = None
        self.errors: list[BaseException] = []
        self.sent: list[int] = []
        self.callbacks = (XFER(self._xfer), DELAY(self._delay), READ_PIN(self._irq), READ_PIN(self._cd),
                          WRITE_PIN(self._sas))  # fmt: skip
        self.cfg = Config(*self.callbacks, None, 0)
        self.ctx = ctypes.create_string_buffer(256)  # larger than supi3_t
        assert self.call("supi3_init", ctypes.byref(self.cfg)) == OK

    def call(self, name: str, *args: object) -> int:
        result = int(getattr(self.lib, name)(self.ctx, *args))
        if self.errors:
            raise self.errors[0]
        return result

    def _xfer(self, _user: int | None, tx: int, rx: ctypes._Pointer[ctypes.c_uint8], s_r: int) -> int:
        try:
            self.sent.append(tx)
            intel = self.up.protocol.mode is Mode.INTEL
            got = self.up.transfer(tx, s_r=bool(s_r)) if intel else self.up.transfer(tx)
            rx[0] = 0 if got is None else got
        except Exception as exc:  # kept and re-raised by call()
            self.errors.append(exc)
            return -1
        return 0

    def _delay(self, _user: int | None, _us: int) -> None:
        return None

    def _irq(self, _user: int | None, level: ctypes._Pointer[ctypes.c_int]) -> int:
        level[0] = self.regs.irq_n
        return 0

    def _cd(self, _user: int | None, level: ctypes._Pointer[ctypes.c_int]) -> int:
        level[0] = self.up.c_d
        return 0

    def _sas(self, _user: int | None, level: int) -> int:
        if level == 0:
            self.up.sas_init()
        return 0

    def read(self, addr: int) -> int:
        value = ctypes.c_uint8()
        assert self.call("supi3_read", ctypes.c_uint8(addr), ctypes.byref(value)) == OK
        return value.value


@pytest.fixture(params=[MOTOROLA, INTEL], ids=["motorola", "intel"])
def board(lib: ctypes.CDLL, request: pytest.FixtureRequest) -> Board:
    b = Board(lib)
    assert b.call("supi3_initialize", ctypes.c_int(request.param)) == OK
    assert b.up.protocol.mode is (Mode.INTEL if request.param == INTEL else Mode.MOTOROLA)
    return b


def test_configure_read_write_as_the_manual(board: Board) -> None:
    board.sent.clear()
    assert board.call("supi3_configure", ctypes.c_uint8(0x82), ctypes.c_uint8(0x01)) == OK
    assert board.sent == [0x4D, 0x82, 0x4C, 0x01]  # 3.4.5
    assert board.regs.bus_id_register() & 0x1FFF == 0x0901
    assert board.read(SET_ADDR) == 0x82
    assert board.read(ID_ADDR) == 0x01
    assert board.call("supi3_write", ctypes.c_uint8(0), ctypes.c_uint8(0x5A)) == OK
    assert board.regs.in_bytes() == b"\x5a"
    board.regs.latch(b"\x33")
    assert board.read(0) == 0x33
    assert board.up.c_d == 0


def test_block_transfer_reads_and_writes_the_data_bytes(board: Board) -> None:
    assert board.call("supi3_configure", ctypes.c_uint8(0x84), ctypes.c_uint8(0x03)) == OK  # 3 bytes
    board.regs.latch(b"\x14\x56\x78")
    out = (ctypes.c_uint8 * 3)()
    data = (ctypes.c_uint8 * 3)(0xA1, 0xB2, 0xC3)
    board.sent.clear()
    assert board.call("supi3_block_transfer", 1, 1, out, data, ctypes.c_size_t(3)) == OK
    assert board.sent[0] == 0xC0 | BLOCK_ADDRESS
    assert bytes(out) == b"\x14\x56\x78"
    assert board.regs.in_bytes() == b"\xa1\xb2\xc3"
    assert board.up.c_d == 0


def test_irq_service_reads_and_clears_the_events(board: Board) -> None:
    assert board.call("supi3_configure", ctypes.c_uint8(0x82), ctypes.c_uint8(0x01)) == OK
    assert board.call("supi3_write", ctypes.c_uint8(IRQ_EN_ADDR), ctypes.c_uint8(0x10)) == OK
    events = ctypes.c_uint8(0xFF)
    board.sent.clear()
    assert board.call("supi3_irq_service", ctypes.byref(events)) == OK
    assert (events.value, board.sent) == (0, [])  # /IRQ high: nothing sent
    board.regs.event("VALID")
    assert board.regs.irq_n == 0
    assert board.call("supi3_irq_service", ctypes.byref(events)) == OK
    assert events.value & 0x7F == 0x10
    assert board.regs.irq_n == 1


def test_a_chip_that_was_not_reset_is_reported_and_recovered_with_sas_init(board: Board) -> None:
    other = INTEL if board.up.protocol.mode is Mode.MOTOROLA else MOTOROLA
    assert board.call("supi3_init", ctypes.byref(board.cfg)) == OK  # the µP restarts, the chip does not
    board.regs.violations.strict = False  # the model reports the locked mode (UP-29); the driver reports it too
    assert board.call("supi3_initialize", ctypes.c_int(other)) == E_NOT_RESET
    assert board.up.c_d == 0  # the driver completed the command
    board.regs.violations.strict = True
    assert board.call("supi3_sas_init") == OK
    assert board.call("supi3_initialize", ctypes.c_int(other)) == OK
    assert board.up.protocol.mode is (Mode.INTEL if other == INTEL else Mode.MOTOROLA)
