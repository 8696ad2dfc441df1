"""The C driver (src/supi3/sdk/c) against the Python reference model: its bytes go through ``UpInterface.transfer``.

The driver is built as a shared library and loaded with ctypes; ``xfer`` is one ``transfer`` (S/R = ``s_r`` in
Intel mode), ``read_cd`` the protocol's C/D, ``read_irq`` the register file's /IRQ, ``set_sas_init`` its SAS_INIT,
``read_io`` its I/O access bit (MFP1, 3.4.14).
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

OK, E_ARG, E_NOT_RESET, E_TIMEOUT = 0, -1, -5, -7
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
        ("read_io", READ_PIN),
    ]


OPTICAL_FIELDS = ("out_length", "out_medium", "out_enable", "branch_length", "branch_medium", "branch_enable",
                  "in_level", "in_enable", "out_level", "branch_level")  # fmt: skip


class Optical(ctypes.Structure):
    """``supi3_optical_t``."""

    _fields_ = [(name, ctypes.c_uint8) for name in OPTICAL_FIELDS]


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

    def __init__(self, lib: ctypes.CDLL, *, io_pin: bool = False) -> None:
        self.lib = lib
        self.regs = RegisterFile(decode("10011", "1110"))  # RB, Init-µP
        self.up = UpInterface(self.regs)
        self.mode: Mode | None = None
        self.errors: list[BaseException] = []
        self.sent: list[int] = []
        self.io_levels: list[int] = []  # I/O pin levels to show, one per read_io; then the register file's bit
        self.callbacks = (XFER(self._xfer), DELAY(self._delay), READ_PIN(self._irq), READ_PIN(self._cd),
                          WRITE_PIN(self._sas))  # fmt: skip
        self.io_callback = READ_PIN(self._io) if io_pin else READ_PIN()
        self.cfg = Config(*self.callbacks, None, 0, self.io_callback)
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

    def _io(self, _user: int | None, level: ctypes._Pointer[ctypes.c_int]) -> int:
        level[0] = self.io_levels.pop(0) if self.io_levels else int(self.regs.io_access)
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
    return _initialized(Board(lib), request.param)


@pytest.fixture(params=[MOTOROLA, INTEL], ids=["motorola", "intel"])
def io_board(lib: ctypes.CDLL, request: pytest.FixtureRequest) -> Board:
    """A board whose ``read_io`` reads the model's I/O access bit (MFP1)."""
    return _initialized(Board(lib, io_pin=True), request.param)


def _initialized(b: Board, mode: int) -> Board:
    assert b.call("supi3_initialize", ctypes.c_int(mode)) == OK
    assert b.up.protocol.mode is (Mode.INTEL if mode == INTEL else Mode.MOTOROLA)
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


def _configured(board: Board) -> None:
    assert board.call("supi3_configure", ctypes.c_uint8(0x82), ctypes.c_uint8(0x01)) == OK


def test_irq_enable_writes_the_enable_register(board: Board) -> None:
    _configured(board)
    board.sent.clear()
    assert board.call("supi3_irq_enable", ctypes.c_uint8(0x50)) == OK
    assert board.sent == [0x4E, 0x50]  # 3.4.14, Fig. 3-19
    assert board.regs.value("IRQ_EN") == 0x50
    assert board.call("supi3_irq_enable", ctypes.c_uint8(0x90)) == E_ARG  # bit 7 reserved (RM-7)
    assert board.sent == [0x4E, 0x50]
    board.regs.event("PCMD")
    board.regs.event("INVALID")  # not enabled: not latched (UP-15)
    assert board.regs.irq_n == 0
    assert board.regs.value("IRQ_EVT") == 0x40


def test_processor_alarm_and_command_reach_the_management_registers(board: Board) -> None:
    _configured(board)
    assert board.call("supi3_irq_enable", ctypes.c_uint8(0x40)) == OK
    board.regs.processor_command(0xC3)  # the master's management message (3.4.9)
    assert board.regs.irq_n == 0
    value = ctypes.c_uint8()
    board.sent.clear()
    assert board.call("supi3_processor_command", ctypes.byref(value)) == OK
    assert (value.value, board.sent) == (0xC3, [0x87, 0x00])
    assert board.call("supi3_processor_alarm", ctypes.c_uint8(0x5A)) == OK
    assert board.sent[2:] == [0x47, 0x5A]
    assert board.regs.processor_alarm == 0x5A
    events = ctypes.c_uint8()
    assert board.call("supi3_irq_service", ctypes.byref(events)) == OK
    assert events.value & 0x7F == 0x40  # D6: processor command (RM-7)


@pytest.mark.parametrize(
    ("raw", "decoded"),
    [
        ((0x00, 0x00, 0x00, 0x00), (0, 0, 0, 0, 0, 0, 0, 0, 0, 0)),
        ((0xFE, 0x3F, 0x8F, 0xF1), (62, 1, 1, 63, 0, 0, 15, 1, 1, 15)),
        ((0x45, 0xC0, 0x07, 0x2A), (5, 1, 0, 0, 1, 1, 7, 0, 10, 2)),
    ],
)
def test_optical_status_decodes_registers_8_to_11(
    board: Board, raw: tuple[int, int, int, int], decoded: tuple[int, ...]
) -> None:
    for name, value in zip(("LENGTH_OUT", "LENGTH_BRANCH", "POWER_IN", "POWER_OUT_BRANCH"), raw, strict=True):
        board.regs.set_optical(name, value)  # 3.4.12, 3.4.13
    status = Optical()
    board.sent.clear()
    assert board.call("supi3_optical_status", ctypes.byref(status)) == OK
    assert board.sent == [0x88, 0x00, 0x89, 0x00, 0x8A, 0x00, 0x8B, 0x00]
    assert tuple(getattr(status, name) for name in OPTICAL_FIELDS) == decoded


def test_poll_reads_register_14_until_the_window_opens_and_keeps_every_event(board: Board) -> None:
    _configured(board)
    assert board.call("supi3_irq_enable", ctypes.c_uint8(0x7F)) == OK
    board.regs.set_io_access(True)
    board.regs.event("VALID")
    events = ctypes.c_uint8(0xFF)
    board.sent.clear()
    assert board.call("supi3_poll_io_window", ctypes.c_uint32(3), ctypes.byref(events)) == E_TIMEOUT
    assert board.sent == [0x8E, 0x00] * 3
    assert events.value == 0x10  # read (and cleared) by the first poll: kept although D7 stayed 1
    assert board.regs.irq_n == 1
    board.regs.event("IB_RESET")
    board.regs.set_io_access(False)  # the latch phase is over: the window opens (Fig. 3-22)
    board.sent.clear()
    assert board.call("supi3_poll_io_window", ctypes.c_uint32(3), ctypes.byref(events)) == OK
    assert (events.value, board.sent) == (0x04, [0x8E, 0x00])
    assert board.call("supi3_poll_io_window", ctypes.c_uint32(0), ctypes.byref(events)) == E_ARG
    assert board.call("supi3_poll_io_window", ctypes.c_uint32(1), None) == E_ARG  # events needed without read_io


def test_poll_with_the_io_pin_sends_nothing(io_board: Board) -> None:
    _configured(io_board)
    assert io_board.call("supi3_irq_enable", ctypes.c_uint8(0x10)) == OK
    io_board.regs.event("VALID")
    io_board.io_levels = [1, 1, 1]
    events = ctypes.c_uint8(0xFF)
    io_board.sent.clear()
    assert io_board.call("supi3_poll_io_window", ctypes.c_uint32(3), ctypes.byref(events)) == E_TIMEOUT
    io_board.regs.set_io_access(True)
    assert io_board.call("supi3_poll_io_window", ctypes.c_uint32(5), None) == E_TIMEOUT
    io_board.io_levels = [1, 1, 0]
    assert io_board.call("supi3_poll_io_window", ctypes.c_uint32(3), ctypes.byref(events)) == OK
    assert (events.value, io_board.sent, io_board.io_levels) == (0, [], [])
    assert io_board.regs.irq_n == 0  # the event is still pending: the pin read cleared nothing
    io_board.regs.set_io_access(False)
    assert io_board.call("supi3_poll_io_window", ctypes.c_uint32(1), None) == OK
