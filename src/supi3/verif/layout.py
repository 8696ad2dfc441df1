"""Packing pins into 32-bit words, stimulus normalisation, model traces and trace comparison.

The harness moves pin values between Python and the simulator as 32-bit words: the design's inputs are packed into
input words and its compared output signals into output words. A signal of up to 32 bits never straddles a word; a
wider one starts a word of its own and takes two. The same layout serves the per-cycle path (one Python integer per
direction, bit ``32 * word + shift``) and the batch path (``uint32`` arrays of shape ``(cycles, words)``).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from numbers import Integral
from operator import itemgetter
from typing import TypeAlias

import numpy as np
import numpy.typing as npt

from supi3.checks import check_instance, fail
from supi3.pinlevel import Pin, PinModel, PinSpecError, check_cycles, compared_signals

__all__ = [
    "CycleMatrix",
    "Stimulus",
    "WordField",
    "WordLayout",
    "apply_inputs",
    "first_mismatch",
    "model_columns",
    "model_trace",
    "stimulus_array",
]  # fmt: skip

CycleMatrix: TypeAlias = npt.NDArray[np.uint64]
"""Values per cycle and signal: shape ``(cycles, signals)``."""

Stimulus: TypeAlias = npt.NDArray[np.integer] | Iterable[Mapping[str, int]]
"""Per-cycle input values: an integer array of shape ``(cycles, inputs)`` with columns in the model's input order,
or an iterable (list, generator) of per-cycle dicts; a pin missing from a dict keeps its previous value (0 at
first)."""

WORD = 32
_WORD_MASK = (1 << WORD) - 1


@dataclass(frozen=True)
class WordField:
    """Where one signal sits in the packed words.

    Attributes
    ----------
    name:
        Pin name (``<pin>_oe`` for an output enable).
    width:
        Bits.
    word:
        Index of the first word.
    shift:
        Bit position within that word.
    enable:
        For a tri-state pin's value: the name of the output enable that gates its comparison.
    """

    name: str
    width: int
    word: int
    shift: int
    enable: str | None = None

    @property
    def offset(self) -> int:
        """Bit position in the words seen as one integer."""
        return WORD * self.word + self.shift

    @property
    def mask(self) -> int:
        """All ones over the field's width, at bit 0."""
        return (1 << self.width) - 1


def _place(signals: Sequence[tuple[str, int, str | None]]) -> tuple[tuple[WordField, ...], int]:
    fields: list[WordField] = []
    word, shift = 0, 0
    for name, width, enable in signals:
        if shift and (width > WORD or shift + width > WORD):
            word, shift = word + 1, 0
        fields.append(WordField(name, width, word, shift, enable))
        if width > WORD:
            word, shift = word + 2, 0
        else:
            shift += width
    return tuple(fields), word + (1 if shift else 0)


def _comparator(fields: Sequence[WordField], index_of: Mapping[str, int]) -> Callable[[Sequence[int], int], bool]:
    # The per-cycle path's hot loop: one expression over the layout's constants instead of a loop over fields,
    # about three times faster in CPython. Only integers from the layout enter the generated source.
    terms = []
    for index, field in enumerate(fields):
        term = f"e[{index}] == (a >> {field.offset}) & {field.mask}"
        if field.enable is not None:
            term = f"(not e[{index_of[field.enable]}] or {term})"
        terms.append(term)
    namespace: dict[str, Callable[[Sequence[int], int], bool]] = {}
    exec(f"def matches(e, a):\n    return {' and '.join(terms)}\n", namespace)
    return namespace["matches"]


class WordLayout:
    """The packing of a model's pins into words.

    Parameters
    ----------
    inputs, outputs:
        The model's pins (see :class:`~supi3.pinlevel.PinModel`).
    """

    def __init__(self, inputs: Sequence[Pin], outputs: Sequence[Pin]) -> None:
        self.inputs = tuple(inputs)
        self.outputs = tuple(outputs)
        names = [pin.name for pin in self.inputs] + [name for name, _, _ in compared_signals(self.outputs)]
        duplicates = sorted({name for name in names if names.count(name) > 1})
        if duplicates:
            raise PinSpecError(f"pin names must be unique, {', '.join(duplicates)} repeated")
        if not self.outputs:
            raise PinSpecError("a model needs at least one output pin to compare")
        if any(pin.tristate for pin in self.inputs):
            raise PinSpecError("only output pins can be tri-state")
        self.in_fields, self.in_words = _place([(pin.name, pin.width, None) for pin in self.inputs])
        self.out_fields, self.out_words = _place(compared_signals(self.outputs))
        self._out_index = {field.name: index for index, field in enumerate(self.out_fields)}
        self._matches = _comparator(self.out_fields, self._out_index)
        self._get_outputs = itemgetter(*[field.name for field in self.out_fields])

    @classmethod
    def of(cls, model: PinModel) -> WordLayout:
        """The layout of ``model``'s pins."""
        return cls(model.inputs, model.outputs)

    @property
    def input_names(self) -> list[str]:
        """Input pin names, in column order."""
        return [field.name for field in self.in_fields]

    @property
    def output_names(self) -> list[str]:
        """Compared output signal names, in comparison order."""
        return [field.name for field in self.out_fields]

    def output_values(self, outputs: Mapping[str, int]) -> tuple[int, ...]:
        """A model's outputs for one cycle as a tuple in comparison order."""
        try:
            values = self._get_outputs(outputs)
        except KeyError as error:
            raise PinSpecError(f"the model's step() returned no value for output {error.args[0]!r}") from None
        return values if isinstance(values, tuple) else (values,)

    def unpack_outputs(self, packed: int) -> tuple[int, ...]:
        """Packed outputs (bit ``32 * word + shift`` of each field) as values in comparison order."""
        return tuple((packed >> field.offset) & field.mask for field in self.out_fields)

    def matches(self, expected: Sequence[int], actual: int) -> bool:
        """Whether the RTL's packed outputs ``actual`` agree with the model's values ``expected`` (in comparison
        order) on every compared signal, skipping tri-state values whose enable the model has at 0."""
        return self._matches(expected, actual)

    def first_difference(self, expected: Sequence[int], actual: Sequence[int]) -> int | None:
        """The index of the first compared output signal that differs in one cycle, or ``None``."""
        for index, field in enumerate(self.out_fields):
            if field.enable is not None and not expected[self._out_index[field.enable]]:
                continue
            if expected[index] != actual[index]:
                return index
        return None

    def input_words(self, stimulus: CycleMatrix) -> npt.NDArray[np.uint32]:
        """Stimulus ``(cycles, inputs)`` packed into ``uint32`` input words ``(cycles, words)``.

        Raises
        ------
        ArgumentError
            ``stimulus`` not a 2-D integer array of one column per input pin, or a value past its pin's width (it
            would spill into the next field of the word, so the design would see other inputs than the model).
        """
        stimulus = _input_matrix(stimulus, self.in_fields)
        # One integer matrix product places every field of up to 32 bits (the fields of a word are disjoint and
        # the stimulus is range-checked, so the sums are exact); a wider field fills its two words alone.
        weights = np.zeros((len(self.in_fields), max(self.in_words, 1)), dtype=np.uint64)
        for index, field in enumerate(self.in_fields):
            if field.width <= WORD:
                weights[index, field.word] = 1 << field.shift
        packed = (stimulus.astype(np.uint64, copy=False) @ weights).astype(np.uint32)
        for index, field in enumerate(self.in_fields):
            if field.width > WORD:
                packed[:, field.word] = stimulus[:, index] & np.uint64(_WORD_MASK)
                packed[:, field.word + 1] = stimulus[:, index] >> np.uint64(WORD)
        return packed

    def output_words(self, trace: CycleMatrix) -> npt.NDArray[np.uint32]:
        """Compared output values ``(cycles, signals)`` packed into ``uint32`` output words ``(cycles, words)``,
        the inverse of :meth:`output_trace`."""
        return self.pack_columns(list(np.ascontiguousarray(trace.T)))

    def pack_columns(self, columns: Sequence[npt.NDArray[np.uint64]]) -> npt.NDArray[np.uint32]:
        """Compared output values, one array per signal (as :func:`model_columns` gives them), packed into
        ``uint32`` output words ``(cycles, words)``."""
        return _pack(self.out_fields, self.out_words, columns)

    def first_word_mismatch(
        self, expected: npt.NDArray[np.uint32], actual: npt.NDArray[np.uint32]
    ) -> tuple[int, int] | None:
        """The first ``(cycle, signal index)`` where two traces of output words differ, gated by output enables,
        or ``None``; the same answer as :func:`first_mismatch` on the unpacked traces."""
        differ = expected ^ actual
        for field in self.out_fields:
            if field.enable is not None:  # a tri-state value counts only while the model enables it
                enable = self.out_fields[self._out_index[field.enable]]
                enabled = (expected[:, enable.word] >> np.uint32(enable.shift)) & np.uint32(1)
                care = np.uint32(field.mask << field.shift) if field.width <= WORD else np.uint32(_WORD_MASK)
                differ[:, field.word] &= ~care | (enabled * care)
                if field.width > WORD:
                    differ[:, field.word + 1] &= ~care | (enabled * care)
        rows = np.flatnonzero(differ.any(axis=1))
        if not rows.size:
            return None
        cycle = int(rows[0])
        signal = self.first_difference(self._unpack_words(expected[cycle]), self._unpack_words(actual[cycle]))
        assert signal is not None, "a differing cycle has a differing signal"
        return cycle, signal

    def _unpack_words(self, words: npt.NDArray[np.uint32]) -> tuple[int, ...]:
        return self.unpack_outputs(sum(int(word) << (WORD * index) for index, word in enumerate(words)))

    def pack_outputs(self, values: Sequence[int]) -> list[int]:
        """One cycle's compared output values (comparison order) as output words.

        Raises
        ------
        PinSpecError
            When a value does not fit its signal.
        """
        packed = 0
        for field, value in zip(self.out_fields, values, strict=True):
            if value >> field.width:
                raise PinSpecError(f"model output {field.name!r} does not fit in {field.width} bits")
            packed |= value << field.offset
        return [(packed >> (WORD * index)) & _WORD_MASK for index in range(self.out_words)]

    def output_trace(self, words: npt.NDArray[np.uint32]) -> CycleMatrix:
        """Output words ``(cycles, words)`` unpacked into compared signals ``(cycles, signals)``."""
        columns = np.empty((words.shape[0], len(self.out_fields)), dtype=np.uint64)
        for index, field in enumerate(self.out_fields):
            if field.width > WORD:
                column = words[:, field.word].astype(np.uint64)
                column |= words[:, field.word + 1].astype(np.uint64) << np.uint64(WORD)
                columns[:, index] = column
            else:  # within one word: shift and mask in 32 bits
                columns[:, index] = (words[:, field.word] >> np.uint32(field.shift)) & np.uint32(field.mask)
        return columns


def _pack(fields: Sequence[WordField], words: int, columns: Sequence[npt.NDArray[np.uint64]]) -> npt.NDArray[np.uint32]:
    """Columns of values (one per field) packed into ``uint32`` words ``(cycles, words)``."""
    cycles = len(columns[0]) if len(columns) else 0
    packed = np.zeros((words, cycles), dtype=np.uint32)  # one contiguous row per word while packing
    for field, column in zip(fields, columns, strict=True):
        packed[field.word] |= column.astype(np.uint32) << np.uint32(field.shift)
        if field.width > WORD:
            packed[field.word + 1] = (column >> np.uint64(WORD)).astype(np.uint32)
    return packed.T


def apply_inputs(cycle: int, values: object, inputs: Sequence[Pin], names: Mapping[str, int],
                 current: list[int]) -> None:  # fmt: skip
    """Set ``current`` (the input levels in ``inputs`` order; ``names`` maps a pin's name to its index) from one
    cycle's dict of a stimulus or a reacting agent: pins it leaves out keep their level.

    Raises
    ------
    PinSpecError
        ``values`` is no mapping, names no input pin, or gives a level that is no integer (``bool``, floats and strings
        are not: a level is never cast) or does not fit the pin; named with ``cycle``. ``current`` may be changed for
        the pins before the one refused.
    """
    if not isinstance(values, Mapping):
        raise PinSpecError(f"cycle {cycle}: stimulus must be a mapping of input pins to values, not {values!r:.80}")
    for name, value in values.items():
        if name not in names:
            raise PinSpecError(f"cycle {cycle}: {name!r} is not an input pin of the model")
        pin = inputs[names[name]]
        level = int(value) if isinstance(value, Integral) and not isinstance(value, bool | np.bool_) else -1
        if level < 0:
            raise PinSpecError(f"cycle {cycle}: input {name!r} must be an integer from 0 to {pin.mask:#x} "
                               f"({pin.width} bits), not {value!r:.40}")  # fmt: skip
        if level > pin.mask:
            raise PinSpecError(f"cycle {cycle}: input {name!r} = {level:#x} exceeds {pin.width} bits")
        current[names[name]] = level


def stimulus_array(stimulus: Stimulus, inputs: Sequence[Pin], max_cycles: int | None = None) -> CycleMatrix:
    """Normalise stimulus to a ``uint64`` array ``(cycles, inputs)``, checking names and value ranges.

    Parameters
    ----------
    stimulus:
        See :data:`Stimulus`.
    inputs:
        The model's input pins.
    max_cycles:
        Take at most this many cycles (needed for an endless generator): an integer from 0, or ``None`` for all.

    Raises
    ------
    PinSpecError
        ``max_cycles`` not ``None`` nor an integer from 0; an array that is not 1-D (one input) or 2-D of shape
        ``(cycles, inputs)``, or holds no integers or negative ones; an iterable whose cycle is no mapping, names no
        input pin, or gives a value that is no integer (``bool``, floats and strings are not: a level is never cast)
        or does not fit the pin, named with its cycle.
    """
    if max_cycles is not None:
        max_cycles = check_cycles("max_cycles", max_cycles, 0)
    if isinstance(stimulus, (str, bytes, Mapping)) or not isinstance(stimulus, (np.ndarray, Iterable)):
        raise PinSpecError(f"stimulus must be an integer array (cycles, inputs) or an iterable of per-cycle dicts, "
                           f"not {stimulus!r:.80}")  # fmt: skip
    if isinstance(stimulus, np.ndarray):
        array = stimulus if stimulus.ndim == 2 else stimulus.reshape(-1, 1) if stimulus.ndim == 1 else stimulus
        if array.ndim != 2 or array.shape[1] != len(inputs):
            raise PinSpecError(f"array stimulus must have shape (cycles, {len(inputs)}), not {stimulus.shape}")
        if not np.issubdtype(array.dtype, np.integer):
            raise PinSpecError(f"array stimulus must hold integers, not {array.dtype}")
        if array.size and array.min() < 0:
            raise PinSpecError("array stimulus must not hold negative values")
        result = array[:max_cycles].astype(np.uint64)
    else:
        names = {pin.name: index for index, pin in enumerate(inputs)}
        current = [0] * len(inputs)
        rows: list[list[int]] = []
        for cycle, values in enumerate(stimulus):
            if max_cycles is not None and cycle >= max_cycles:
                break
            apply_inputs(cycle, values, inputs, names, current)
            rows.append(list(current))
        result = np.array(rows, dtype=np.uint64).reshape(len(rows), len(inputs))
    for index, pin in enumerate(inputs):
        if result.size and int(result[:, index].max()) > pin.mask:
            cycle = int(np.argmax(result[:, index] > np.uint64(pin.mask)))
            value = int(result[cycle, index])
            raise PinSpecError(f"cycle {cycle}: input {pin.name!r} = {value:#x} exceeds {pin.width} bits")
    return result


def model_columns(model: PinModel, stimulus: CycleMatrix, layout: WordLayout) -> list[npt.NDArray[np.uint64]]:
    """Reset ``model`` and run it over ``stimulus``; one array per compared output signal, in comparison order.

    A model that also offers ``run(inputs: Mapping[str, array]) -> Mapping[str, array]`` (whole traces at once,
    the same cycles as repeated :meth:`~supi3.pinlevel.PinModel.step`) is run that way, which is much
    faster for event-driven models.

    Raises
    ------
    PinSpecError
        When an output value does not fit its signal, naming the first such cycle.
    """
    model.reset()
    names = layout.input_names
    bulk = getattr(model, "run", None)
    if callable(bulk):
        outputs = bulk({name: stimulus[:, index] for index, name in enumerate(names)})
        columns = [_unsigned(np.asarray(outputs[field.name])) for field in layout.out_fields]
    else:
        step = model.step
        values = layout.output_values
        rows = [values(step(dict(zip(names, row, strict=True)))) for row in stimulus.tolist()]
        columns = list(np.array(rows, dtype=np.uint64).reshape(len(rows), len(layout.out_fields)).T)
    for field, column in zip(layout.out_fields, columns, strict=True):
        if column.size and column.max() > field.mask:
            cycle = int(np.argmax(column > np.uint64(field.mask)))
            raise PinSpecError(f"cycle {cycle}: model output {field.name!r} does not fit in {field.width} bits")
    return columns


def _unsigned(column: npt.NDArray[np.generic]) -> npt.NDArray[np.uint64]:
    # A negative value becomes a huge one, which the width check then names.
    return column.view(np.uint64) if column.dtype == np.int64 else column.astype(np.uint64)


def model_trace(model: PinModel, stimulus: CycleMatrix, layout: WordLayout) -> CycleMatrix:
    """Reset ``model`` and run it over ``stimulus``; the compared outputs per cycle ``(cycles, signals)``
    (see :func:`model_columns`)."""
    columns = model_columns(model, stimulus, layout)
    return np.stack(columns, axis=1) if columns else np.zeros((stimulus.shape[0], 0), dtype=np.uint64)


def first_mismatch(layout: WordLayout, expected: CycleMatrix, actual: CycleMatrix) -> tuple[int, int] | None:
    """The first ``(cycle, signal index)`` where two output traces (values within their signals' widths) differ,
    gated by output enables, or ``None``.

    Within the first differing cycle the lowest signal index (comparison order) is reported. The traces are compared
    as packed words, like the batch path (:meth:`WordLayout.first_word_mismatch`).

    Raises
    ------
    ArgumentError
        ``layout`` not a :class:`WordLayout`; a trace not a 2-D integer array of one column per compared signal, a
        value outside its signal's width (packed, it spilled into the next signal: a difference named the wrong
        pin, or two differences cancelled), or the traces of different lengths.
    """
    check_instance("layout", layout, WordLayout)
    expected = _output_trace("expected", expected, layout)
    actual = _output_trace("actual", actual, layout)
    if actual.shape[0] != expected.shape[0]:
        raise fail("actual", f"as many cycles as expected ({expected.shape[0]})", f"{actual.shape[0]} cycles")
    return layout.first_word_mismatch(layout.output_words(expected), layout.output_words(actual))


def _within(field: WordField) -> str:
    return f"a value of {field.name!r} within {field.width} bit{'s' if field.width != 1 else ''}"


def _input_matrix(stimulus: object, fields: Sequence[WordField]) -> CycleMatrix:
    """``stimulus`` as a ``(cycles, inputs)`` integer array whose every value fits its pin, else the named error."""
    wanted = f"a (cycles, {len(fields)}) integer array of the input pins"
    if not isinstance(stimulus, np.ndarray) or stimulus.ndim != 2 or stimulus.shape[1] != len(fields) \
            or (stimulus.size and stimulus.dtype.kind not in "iu"):
        raise fail("stimulus", wanted, stimulus)
    if stimulus.size:
        if stimulus.dtype.kind == "i" and stimulus.min() < 0:
            cycle, index = np.argwhere(stimulus < 0)[0].tolist()
            raise fail(f"stimulus[{cycle}, {index}]", _within(fields[index]), stimulus[cycle, index].item())
        masks = np.array([field.mask for field in fields], dtype=np.uint64)
        over = stimulus.astype(np.uint64, copy=False) > masks
        if over.any():
            cycle, index = np.argwhere(over)[0].tolist()
            raise fail(f"stimulus[{cycle}, {index}]", _within(fields[index]), stimulus[cycle, index].item())
    return stimulus


def _output_trace(name: str, trace: object, layout: WordLayout) -> CycleMatrix:
    """``trace`` as a ``(cycles, signals)`` array of compared output values, each within its signal's width."""
    signals = len(layout.out_fields)
    wanted = f"a (cycles, {signals}) integer array of the compared outputs"
    try:
        array = np.asarray(trace)
    except (TypeError, ValueError) as error:
        raise fail(name, wanted, trace) from error
    if array.ndim != 2 or array.shape[1] != signals or (array.size and array.dtype.kind not in "iu"):
        raise fail(name, wanted, trace)
    for index, field in enumerate(layout.out_fields):
        column = array[:, index]
        bad = (column < 0) | (column > field.mask) if column.dtype.kind == "i" else column > field.mask
        if bad.any():
            cycle = int(np.argmax(bad))
            raise fail(f"{name}[{cycle}, {index}]", _within(field), column[cycle].item())
    return array.astype(np.uint64, copy=False)
