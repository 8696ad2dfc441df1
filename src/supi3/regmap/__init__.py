"""The serial µP interface register map of the SUPI 3 OPC, declared once, and every output generated from it.

Ref: IBS SUPI 3 OPC UM E rev. 05, 3.4.3-3.4.14, Table 3-10. The model, the RTL and the SDK import
:data:`REGISTER_MAP` (and the layouts and helpers below); the documentation and ``supi3_regs.h`` are rendered
from it by :func:`render`.
"""

from supi3.regmap.core import (
    Access,
    AccessDirection,
    ByteLayout,
    Enumerator,
    Field,
    Port,
    Register,
    RegisterMap,
    RegisterMapError,
    Reset,
)
from supi3.regmap.export import (
    CHECKED_IN,
    FORMATS,
    render,
    to_c_header,
    to_html,
    to_json,
    to_markdown,
    to_systemrdl,
    write_checked_in,
)
from supi3.regmap.registers import (
    COMMAND_BYTE,
    INIT_BYTE,
    INTERRUPT_SOURCES,
    REGISTER_MAP,
    CommandByte,
    InterruptSource,
    SetConfig,
    decode_command,
    decode_set,
    encode_command,
)

__all__ = [
    "CHECKED_IN",
    "COMMAND_BYTE",
    "FORMATS",
    "INIT_BYTE",
    "INTERRUPT_SOURCES",
    "REGISTER_MAP",
    "Access",
    "AccessDirection",
    "ByteLayout",
    "CommandByte",
    "Enumerator",
    "Field",
    "InterruptSource",
    "Port",
    "Register",
    "RegisterMap",
    "RegisterMapError",
    "Reset",
    "SetConfig",
    "decode_command",
    "decode_set",
    "encode_command",
    "render",
    "to_c_header",
    "to_html",
    "to_json",
    "to_markdown",
    "to_systemrdl",
    "write_checked_in",
]
