# SPDX-License-Identifier: BSD-3-Clause
"""rotacal: calibration of the rotary axes of 5-axis machine tools.

A typed wrapper over the private extension ``rotacal._core``: sessions are numpy-backed
objects, analyses return result objects whose ``to_dict()`` is the JSON the CLI prints.
"""

from ._core import (  # noqa: F401
    BallbarMachineModel,
    BallbarSession,
    DegenerateGeometry,
    Effect,
    Error,
    InvalidArgument,
    IoError,
    MachineType,
    ParseError,
    ProbeSession,
    RtestSession,
    compensate_commands,
    effect_catalogue,
    forward,
    hyper_circle_fit,
    kasa_circle_fit,
    location_error_names,
    machine_name,
    parse_machine_type,
    simulate_ballbar,
    sphere_fit,
    svd_plane_fit,
    verify_compensation,
)
from ._core import (
    BallbarPlan,
    BallbarSetup,
    BallbarTest,
    NcDialect,
    NcProgramOptions,
    RadialSide,
    parse_ballbar_test,
    parse_nc_dialect,
    parse_radial_side,
    plan_ballbar_test,
    write_nc_program,
)  # noqa: F401,E501
from .analysis import identify  # noqa: F401
from .ballbar import predict  # noqa: F401
from .machines import TABLE2_ERRORS, random_location_errors  # noqa: F401
from .diagnosis import diagnose, plausible_sizes, uncertainty_budget  # noqa: F401
from .models import ballbar_model_from_dict, load_model, save_model  # noqa: F401
from .outputs import write_output  # noqa: F401
from .results import DiagnosisResult, Identification  # noqa: F401
from .probe import identify_probe, simulate_probe  # noqa: F401
from .rtest import identify_rtest, monte_carlo_rtest  # noqa: F401
from .sessions import check_plausible, load, save  # noqa: F401
from .version import __version__  # noqa: F401
