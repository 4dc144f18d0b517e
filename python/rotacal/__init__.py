"""rotacal: calibration of the rotary axes of 5-axis machine tools.

A typed wrapper over the private extension ``rotacal._core``.
"""
from ._core import (  # noqa: F401
    DegenerateGeometry,
    Error,
    InvalidArgument,
    IoError,
    MachineType,
    ParseError,
    forward,
    location_error_names,
    machine_name,
    parse_machine_type,
)

__version__ = "0.1.0"
