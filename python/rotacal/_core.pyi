"""Type stubs for the native extension rotacal._core (units: mm, rad inside, deg in sessions)."""
from __future__ import annotations

import enum
from typing import Callable, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

Array = npt.NDArray[np.float64]
ArrayLike = npt.ArrayLike

class Error(RuntimeError): ...
class InvalidArgument(Error): ...
class DegenerateGeometry(Error): ...
class ParseError(Error): ...
class IoError(Error): ...

class MachineType(enum.Enum):
    AC_trt: MachineType
    BC_trt: MachineType

def parse_machine_type(text: str) -> MachineType: ...
def machine_name(machine: MachineType) -> str: ...
def location_error_names(machine: MachineType) -> list[str]: ...
def forward(machine: MachineType, errors: ArrayLike, angles: ArrayLike, q_table: ArrayLike) -> Array: ...

class Effect:
    def __init__(self, id: str) -> None: ...
    id: str
    cause: str
    num_params: int
    param_names: list[str]
    param_units: list[str]
    harmonic: int
    def applies_to(self, machine: MachineType) -> bool: ...

def effect_catalogue(machine: MachineType, max_harmonic: int = 4) -> list[Effect]: ...

# ---------------------------------------------------------------- sessions
class BallbarSession:
    def __init__(self, machine: MachineType, ballbar_length: float, pivot: ArrayLike, tests: Sequence[str],
                 time: ArrayLike, xyz: ArrayLike, angles_deg: ArrayLike, length: ArrayLike,
                 noise_um: Optional[float] = None) -> None: ...
    machine: MachineType
    ballbar_length: float
    pivot: Array
    noise_um: Optional[float]
    metadata: dict[str, str]
    tests: list[str]
    test_names: list[str]
    time: Array
    xyz: Array
    angles_deg: Array
    length: Array
    annotations: list[tuple[int, str]]
    def with_lengths(self, length: ArrayLike) -> BallbarSession: ...
    def __len__(self) -> int: ...

class RtestSession:
    machine: MachineType
    nests: dict[str, Array]
    probe_dirs: dict[int, Array]
    noise_um: Optional[float]
    metadata: dict[str, str]
    setups: list[str]
    time: Array
    angles_deg: Array
    xyz: Array
    d: Array
    def with_displacements(self, d: ArrayLike) -> RtestSession: ...
    def __len__(self) -> int: ...

def read_session(path: str) -> Union[BallbarSession, RtestSession]: ...
def read_ballbar(path: str) -> BallbarSession: ...
def read_rtest(path: str) -> RtestSession: ...
def write_ballbar(session: BallbarSession, path: str) -> None: ...
def write_rtest(session: RtestSession, path: str) -> None: ...
def format_ballbar(session: BallbarSession) -> str: ...
def format_rtest(session: RtestSession) -> str: ...

# ---------------------------------------------------------------- fits
class CircleFit:
    centre: Array
    radius: float
    covariance: Array
    rms: float
    n: int

class SphereFit:
    centre: Array
    radius: float
    covariance: Array
    rms: float
    n: int
    converged: bool

class PlaneFit:
    centroid: Array
    normal: Array
    singular_values: Array
    normal_covariance: Array
    rms: float
    n: int

def hyper_circle_fit(points: ArrayLike, sigma: float = 0.0, refine: bool = False) -> CircleFit: ...
def kasa_circle_fit(points: ArrayLike, sigma: float = 0.0, refine: bool = False) -> CircleFit: ...
def sphere_fit(points: ArrayLike, radius: Optional[float] = None, sigma: float = 0.0) -> SphereFit: ...
def svd_plane_fit(points: ArrayLike, normal_hint: ArrayLike = ..., sigma: float = 0.0) -> PlaneFit: ...

# ---------------------------------------------------------------- ballbar
class ParameterEstimate:
    name: str
    value: float
    std: float
    unit: str
    observable: bool

class BallbarMachineModel:
    def __init__(self, machine: MachineType, errors: ArrayLike, pivot: ArrayLike, effects: Sequence[str] = ...,
                 effect_params: Sequence[float] = ...) -> None: ...
    machine: MachineType
    errors: Array
    pivot: Array
    effects: list[str]
    effect_params: list[float]

class BallbarIdentification:
    method: str
    model: BallbarMachineModel
    parameters: list[ParameterEstimate]
    covariance: Array
    residuals: Array
    residual_rms_um: float
    sigma_um: float
    n_samples: int
    converged: bool
    iterations: int
    unobservable: list[str]
    notes: list[str]

def identify_joint(session: BallbarSession, fit_length_offset: bool = False, effects: Sequence[str] = ...,
                   tests: Sequence[str] = ...) -> BallbarIdentification: ...
def identify_paper(session: BallbarSession) -> BallbarIdentification: ...
def simulate_ballbar(commanded: BallbarSession, truth: BallbarMachineModel, noise_um: float = 0.5, seed: int = 1,
                     declare_noise: bool = True) -> BallbarSession: ...
def predict_session_lengths(model: BallbarMachineModel, session: BallbarSession) -> Array: ...
def compensate_commands(nominal: BallbarSession, identified: ArrayLike, machine: MachineType) -> BallbarSession: ...

class CompensationRow:
    name: str
    unit: str
    before: float
    after: float
    std_after: float
    change_percent: float

class CompensationReport:
    rows: list[CompensationRow]
    before: BallbarIdentification
    after: BallbarIdentification

def verify_compensation(commanded: BallbarSession, truth: BallbarMachineModel, noise_um: float = 0.5,
                        seed: int = 1) -> CompensationReport: ...

# planning (test_plan.hpp, nc_program.hpp)
class BallbarSetup:
    def __init__(self) -> None: ...
    machine: MachineType
    ballbar_length: float
    pivot: Array
    tilt_range_deg: Array
    rot_range_deg: Array
    step_deg: float
    feed_mm_per_min: float
    feed_deg_per_min: float

class BallbarPlan:
    num_samples: int
    duration: float
    labels: list[str]
    time: Array
    p_table: Array
    angles_deg: Array
    machine_axes: Array
    def commanded_session(self) -> BallbarSession: ...

def plan_ballbar_test(setup: BallbarSetup, identified: Optional[ArrayLike] = None) -> BallbarPlan: ...
def write_nc_program(plan: BallbarPlan, dialect: object, options: object = ...) -> str: ...

# ---------------------------------------------------------------- diagnosis
class DiagnosisOptions:
    def __init__(self) -> None: ...
    max_harmonic: int
    max_findings: int
    alpha: float
    min_delta_bic: float
    cv_blocks: int
    only: list[str]

class Gain:
    rms_before_um: float
    rms_after_um: float
    delta_bic: float
    cv_rms_before_um: float
    cv_rms_after_um: float
    f_pvalue: float

class Finding:
    effect: str
    cause: str
    parameters: list[ParameterEstimate]
    gain: Gain

class Diagnosis:
    machine: MachineType
    findings: list[Finding]
    seconds: float

def diagnose_ballbar(session: BallbarSession, options: DiagnosisOptions = ...,
                     reference: Optional[BallbarSession] = None) -> Diagnosis: ...
def diagnose_rtest(session: RtestSession, options: DiagnosisOptions = ...) -> Diagnosis: ...

# ---------------------------------------------------------------- R-test
class RtestBasis:
    def __init__(self, b_degree: int = 6, c_harmonics: int = 2, c_b_degree: int = 1,
                 gamma_cb: bool = False) -> None: ...
    b_degree: int
    c_harmonics: int
    c_b_degree: int
    gamma_cb: bool
    def coefficient_names(self) -> list[str]: ...

class RtestJointModel:
    def __init__(self, machine: MachineType, basis: RtestBasis, params: ArrayLike, covariance: ArrayLike,
                 observable: Sequence[bool]) -> None: ...
    machine: MachineType
    basis: RtestBasis
    params: Array
    covariance: Array
    observable: list[bool]
    def readings(self, q: ArrayLike, angles: ArrayLike) -> tuple[Array, Array]: ...
    def table_errors(self, q: ArrayLike, angles: ArrayLike) -> tuple[Array, Array]: ...
    def w_by(self, B: ArrayLike) -> tuple[Array, Array]: ...
    def w_cb(self, angles: ArrayLike) -> tuple[Array, Array]: ...

class RtestJointIdentification:
    method: str
    model: RtestJointModel
    parameters: list[ParameterEstimate]
    covariance: Array
    probe_zeros: dict[str, Array]
    residuals: Array
    residual_rms_um: float
    sigma_um: float
    n_samples: int
    converged: bool
    iterations: int
    unobservable: list[str]
    notes: list[str]

class RtestPaperIdentification:
    method: str
    b_deg: list[float]
    c_deg: list[float]
    residual_rms_um: float
    n_samples: int
    unobservable: list[str]
    notes: list[str]

def identify_rtest_joint(session: RtestSession, basis: RtestBasis = ...) -> RtestJointIdentification: ...
def identify_rtest_paper(session: RtestSession) -> RtestPaperIdentification: ...
def rtest_error_map(identification: object, *args: object) -> str: ...
def predict_rtest_session(model: RtestJointModel, session: RtestSession,
                          probe_zeros: dict[str, ArrayLike] = ...) -> RtestSession: ...
def rtest_prediction_rms_um(model: RtestJointModel, session: RtestSession) -> float: ...
def simulate_rtest(machine: MachineType, errors: ArrayLike, effects: Sequence[str], effect_params: Sequence[float],
                   b_deg: Sequence[float], c_deg: Sequence[float], nests: ArrayLike, dwell_s: float,
                   noise_um: float, probe_zero_um: float, probe_dirs: Optional[ArrayLike] = None,
                   write_d: bool = True, seed: int = 1) -> tuple[RtestSession, Array]: ...
def rtest_readings(machine: MachineType, errors: ArrayLike, effects: Sequence[str], effect_params: Sequence[float],
                   q: ArrayLike, angles: ArrayLike, time: ArrayLike) -> Array: ...

class ProbeCalibration:
    dirs: Array
    gains: Array
    zeros: Array
    direction_std_rad: Array
    gain_std: Array
    residuals: Array
    residual_rms_um: float
    sigma_um: float

class SphereOffsetCalibration:
    offset: Array
    offset_std: Array
    centre: Array
    residual_rms_um: float

def calibrate_probe_directions(moves: ArrayLike, readings: ArrayLike) -> ProbeCalibration: ...
def simulate_probe_calibration(dirs: ArrayLike, zeros: ArrayLike, moves: ArrayLike, noise_um: float,
                               seed: int) -> Array: ...
def default_calibration_moves(step_mm: float = 0.5) -> Array: ...
def calibrate_sphere_offset(dirs: ArrayLike, angles: ArrayLike, readings: ArrayLike) -> SphereOffsetCalibration: ...
def simulate_spindle_indexing(dirs: ArrayLike, zeros: ArrayLike, offset: ArrayLike, centre: ArrayLike,
                              angles: Sequence[float], noise_um: float, seed: int) -> Array: ...
def displacements_from_raw(session: RtestSession, dirs: Optional[ArrayLike] = None) -> RtestSession: ...
def compensate_sphere_offset(session: RtestSession, offset: ArrayLike) -> RtestSession: ...

# --- hw: virtual instruments and recorders (include/rotacal/hw)
class SerialError(IoError): ...
class DeviceDisconnected(SerialError): ...

class FaultInjection:
    garbage_every: int
    corrupt_every: int
    drop_every: int
    split_frames: bool
    close_after: int
    silence_after: int
    def __init__(self) -> None: ...

class VirtualBallbar:
    def __init__(self, plan: BallbarPlan, truth: BallbarMachineModel, noise_um: float = 0.5, seed: int = 1,
                 rate_hz: float = 1000.0, speed: float = 1.0, baud: int = 115200,
                 faults: FaultInjection = ...) -> None: ...
    @property
    def port(self) -> str: ...
    @property
    def finished(self) -> bool: ...
    def start(self) -> None: ...
    def stop(self) -> None: ...
    def stats(self) -> dict: ...

class VirtualRtest:
    def __init__(self, machine: MachineType, errors: ArrayLike, effects: Sequence[str],
                 effect_params: Sequence[float], b_deg: Sequence[float], c_deg: Sequence[float],
                 nests: ArrayLike, dwell_s: float, noise_um: float, probe_zero_um: float, probe_dirs: ArrayLike,
                 seed: int, mode: str = "keyence", rate_hz: float = 100.0, speed: float = 1.0,
                 baud: int = 115200, faults: FaultInjection = ...) -> None: ...
    @property
    def port(self) -> str: ...
    @property
    def finished(self) -> bool: ...
    @property
    def program(self) -> RtestSession: ...
    @property
    def probe_zeros(self) -> Array: ...
    def start(self) -> None: ...
    def stop(self) -> None: ...
    def stats(self) -> dict: ...

class RecordSummary:
    rows: int
    frames: int
    lost: int
    crc_errors: int
    malformed: int
    garbage_bytes: int
    over_range: int
    timeouts: int
    reason: str
    detail: str
    def describe(self) -> str: ...

def record_ballbar(port: str, plan: BallbarPlan, path: str, baud: int = 115200, rate_hz: float = 1000.0,
                   zero: bool = False, silence_timeout_s: float = 3.0,
                   progress: Optional[Callable[[int, int, int, float, float], bool]] = None) -> RecordSummary: ...
def record_rtest(port: str, mode: str, program: RtestSession, dwell_s: float, probe_dirs: ArrayLike, path: str,
                 baud: int = 115200, rate_hz: float = 100.0, speed: float = 1.0, silence_timeout_s: float = 3.0,
                 progress: Optional[Callable[[int, int, int, float, float], bool]] = None) -> RecordSummary: ...
def list_serial_ports() -> list[tuple[str, str, str]]: ...
