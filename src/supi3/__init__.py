"""supi3: model, reference RTL, verification kit and firmware SDK for the IBS SUPI 3 OPC INTERBUS slave chip."""

from supi3.config import DeviceConfig, Interface, MfpKind, Variant, decode
from supi3.errors import ConfigurationError, Supi3Error

__all__ = ["ConfigurationError", "DeviceConfig", "Interface", "MfpKind", "Supi3Error", "Variant", "decode"]
__version__ = "0.1.0"
