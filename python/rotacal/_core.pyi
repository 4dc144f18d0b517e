# SPDX-License-Identifier: BSD-3-Clause
"""
rotacal native core (use the rotacal package, not this module)
"""
from __future__ import annotations
import collections.abc
import numpy
import numpy.typing
import typing
__all__: list[str] = ['Alternative', 'Ambiguity', 'AngleTable', 'AxisAngleMap', 'BallbarDesign', 'BallbarDesignOptions', 'BallbarIdentification', 'BallbarMachineModel', 'BallbarMonteCarlo', 'BallbarPlan', 'BallbarSession', 'BallbarSetup', 'BallbarTest', 'BudgetLine', 'CandidateScore', 'CircleFit', 'CircularAnalysis', 'CircularDiagnosis', 'CircularDiagnosisOptions', 'CircularDirection', 'CircularEffect', 'CircularFinding', 'CircularPairResult', 'CircularPlanResult', 'CircularPlane', 'CircularRun', 'CircularRunResult', 'CircularSimulationOptions', 'CircularTestPlan', 'CompensationReport', 'CompensationRow', 'CompensationTable', 'CompensationTables', 'ControllerExport', 'ControllerValue', 'DegenerateGeometry', 'DesignCandidate', 'DeviceDisconnected', 'Diagnosis', 'DiagnosisBaseline', 'DiagnosisOptions', 'Effect', 'Error', 'ErrorDisposition', 'FanucPitchOptions', 'FaultInjection', 'Finding', 'FitSummary', 'Gain', 'GroupResidual', 'Identification', 'InvalidArgument', 'IoError', 'LinearAxisErrors', 'LocationBudget', 'MachineType', 'ModelFit', 'MonteCarloParameter', 'MultiDiagnosis', 'MultiDiagnosisSession', 'MultiDisagreement', 'MultiIdentification', 'MultiSessionResult', 'NcDialect', 'NcProgramOptions', 'NoiseModel', 'NoiseModelOptions', 'NoiseStream', 'ParameterEstimate', 'ParameterShift', 'ParseError', 'PlanSegment', 'PlaneFit', 'PlausibilityOptions', 'PlausibilityReport', 'PlausibleSizes', 'ProbeCalibration', 'ProbeDesign', 'ProbeDesignCandidate', 'ProbeDesignOptions', 'ProbeIdentification', 'ProbeMonteCarlo', 'ProbeSeparatingCandidate', 'ProbeSeparationDesign', 'ProbeSeparationOptions', 'ProbeSession', 'ProbeSphereTrial', 'RadialSide', 'RealtimeModel', 'RecordSummary', 'RtestBasis', 'RtestDesign', 'RtestDesignCandidate', 'RtestDesignOptions', 'RtestJointIdentification', 'RtestJointModel', 'RtestMonteCarlo', 'RtestPaperIdentification', 'RtestPattern', 'RtestSeparatingCandidate', 'RtestSeparationDesign', 'RtestSeparationOptions', 'RtestSession', 'RtestSimOptions', 'SegmentKind', 'SeparatingCandidate', 'SeparationDesign', 'SeparationOptions', 'SerialError', 'SphereFit', 'SphereOffsetCalibration', 'SweepDirection', 'TableMotionOverlap', 'TransitionArc', 'UncertaintyBudget', 'Unexplained', 'UnobservableEffect', 'VirtualBallbar', 'VirtualCircularBallbar', 'VirtualRtest', 'analyze_circular', 'angle_maps', 'ballbar_model_document', 'ballbar_model_from_document', 'box_least_squares', 'budget_diagnosis_ballbar', 'builtin_machine_names', 'calibrate_probe_directions', 'calibrate_sphere_offset', 'check_json_bounds', 'check_model_machine', 'check_output', 'check_plausible', 'check_rtest_pattern', 'circular_catalogue', 'circular_commanded_session', 'circular_label', 'comment_lines', 'compensate_commands', 'compensate_sphere_offset', 'controller_parameter_names', 'default_axial_c_tilt_deg', 'default_ballbar_tests', 'default_calibration_moves', 'default_probe_poses_deg', 'default_rtest_pattern', 'default_tilt_range_deg', 'design_ballbar_separation', 'design_ballbar_test', 'design_probe_separation', 'design_probe_test', 'design_rtest_separation', 'design_rtest_test', 'diagnose_ballbar', 'diagnose_circular', 'diagnose_probe', 'diagnose_rtest', 'diagnose_sessions', 'displacements_from_raw', 'effect_catalogue', 'estimate_noise_model', 'evaluate_rtest_design', 'export_controller', 'fanuc_pitch_tables', 'format_ballbar', 'format_model_document', 'format_probe', 'format_rtest', 'forward', 'hyper_circle_fit', 'identify_joint', 'identify_multi', 'identify_paper', 'identify_probe', 'identify_probe_cycles', 'identify_rtest_joint', 'identify_rtest_paper', 'identify_runs', 'identify_thermal', 'is_machine_effect', 'is_rotary_test', 'is_thermal_session', 'isg_tables', 'kasa_circle_fit', 'linuxcnc_comp_tables', 'list_serial_ports', 'location_error_names', 'machine_name', 'monte_carlo_joint', 'monte_carlo_probe', 'monte_carlo_rtest', 'multi_model_document', 'noise_ar1', 'noise_pink', 'noise_probe_zero_wander', 'noise_thermal_wander', 'parse_ballbar_test', 'parse_circular_direction', 'parse_circular_plane', 'parse_machine_type', 'parse_model_document', 'parse_nc_dialect', 'parse_radial_side', 'parse_sweep_direction', 'plan_ballbar_test', 'plan_circular_test', 'predict_rtest_session', 'predict_session_lengths', 'predict_thermal', 'probe_effect_catalogue', 'probe_model_document', 'read_ballbar', 'read_instrument_session', 'read_linuxcnc_probe_log', 'read_model_document', 'read_probe', 'read_rtest', 'read_session', 'realtime_model_of_blob', 'realtime_model_of_file', 'record_ballbar', 'record_circular_ballbar', 'record_rtest', 'record_run', 'refuse_disagreeing', 'rtest_error_map', 'rtest_joint_model_document', 'rtest_map_names', 'rtest_prediction_rms_um', 'rtest_readings', 'run_label', 'simulate_ballbar', 'simulate_circular', 'simulate_probe', 'simulate_probe_calibration', 'simulate_rtest', 'simulate_spindle_indexing', 'simulate_thermal', 'sinumerik_eec_tables', 'sinumerik_tables', 'sphere_fit', 'svd_plane_fit', 'table_motion_overlap', 'test_label', 'uncertainty_budget_ballbar', 'uncertainty_budget_probe', 'uncertainty_budget_rtest', 'uncertainty_budget_rtest_identification', 'verify_compensation', 'write_ballbar', 'write_circular_nc_program', 'write_model_document', 'write_nc_program', 'write_output', 'write_probe', 'write_probe_nc_program', 'write_rtest']
class Alternative:
    @property
    def aliased(self) -> bool:
        ...
    @property
    def correlation(self) -> float:
        ...
    @property
    def delta_bic(self) -> float:
        ...
    @property
    def effect(self) -> str:
        ...
    @property
    def in_group(self) -> bool:
        ...
    @property
    def weight(self) -> float:
        ...
class Ambiguity:
    @property
    def correlation(self) -> float:
        ...
    @property
    def delta_bic(self) -> float:
        ...
    @property
    def effects(self) -> list[str]:
        ...
    @property
    def separating_test(self) -> str:
        ...
class AngleTable:
    @property
    def angle_deg(self) -> list[float]:
        ...
    @property
    def axis(self) -> str:
        ...
    @property
    def count(self) -> list[int]:
        ...
    @property
    def gain(self) -> Gain:
        ...
    @property
    def group(self) -> str:
        ...
    @property
    def std_um(self) -> list[float]:
        ...
    @property
    def value_um(self) -> list[float]:
        ...
class AxisAngleMap:
    """
    One rotary axis' error terms at equal spacing.
    """
    @property
    def angle_deg(self) -> list[float]:
        ...
    @property
    def axis(self) -> str:
        ...
    @property
    def max_interpolation_error(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        (7,) worst absolute difference of the model and the linear interpolation between the points
        """
    @property
    def names(self) -> typing.Annotated[list[str], "FixedSize(7)"]:
        """
        E_X<axis> .. E_C<axis>, positioning_<axis>
        """
    @property
    def notes(self) -> list[str]:
        """
        what the map leaves out
        """
    @property
    def samples_between(self) -> int:
        ...
    @property
    def sources(self) -> list[str]:
        """
        the model's terms that feed it
        """
    @property
    def units(self) -> typing.Annotated[list[str], "FixedSize(7)"]:
        ...
    @property
    def values(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        (n, 7) the terms at angle_deg (mm, rad)
        """
class BallbarDesign:
    """
    The chosen set-up and the default one.
    """
    @property
    def baseline(self) -> DesignCandidate:
        ...
    @property
    def best(self) -> DesignCandidate:
        ...
    @property
    def candidates(self) -> list[DesignCandidate]:
        ...
    @property
    def ratio(self) -> float:
        ...
    @property
    def time_budget_s(self) -> float:
        ...
class BallbarDesignOptions:
    """
    Options of design_ballbar_test (defaults).
    """
    def __init__(self) -> None:
        ...
    @property
    def bar_lengths_mm(self) -> list[float]:
        ...
    @bar_lengths_mm.setter
    def bar_lengths_mm(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def base(self) -> BallbarSetup:
        """
        the default set-up: machine, tests, ranges, feeds
        """
    @base.setter
    def base(self, arg0: BallbarSetup) -> None:
        ...
    @property
    def effects_of_concern(self) -> list[str]:
        ...
    @effects_of_concern.setter
    def effects_of_concern(self, arg1: collections.abc.Sequence[str]) -> None:
        ...
    @property
    def noise_rho(self) -> float:
        """
        AR(1) coefficient between samples
        """
    @noise_rho.setter
    def noise_rho(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def noise_um(self) -> float:
        ...
    @noise_um.setter
    def noise_um(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def pivot_x_mm(self) -> list[float]:
        ...
    @pivot_x_mm.setter
    def pivot_x_mm(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def pivot_z_mm(self) -> list[float]:
        ...
    @pivot_z_mm.setter
    def pivot_z_mm(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def reference_radius_mm(self) -> float:
        ...
    @reference_radius_mm.setter
    def reference_radius_mm(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def sample_rate_hz(self) -> float:
        ...
    @sample_rate_hz.setter
    def sample_rate_hz(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def time_budget_s(self) -> float:
        """
        0: the default set-up's run time
        """
    @time_budget_s.setter
    def time_budget_s(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def travel_max(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @travel_max.setter
    def travel_max(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def travel_min(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        X, Y, Z, mm (formats.md frame)
        """
    @travel_min.setter
    def travel_min(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
class BallbarIdentification(Identification):
    @property
    def model(self) -> BallbarMachineModel:
        ...
class BallbarMachineModel:
    """
    Location errors, actual pivot and effects of a machine.
    """
    def __init__(self, machine: MachineType, errors: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], pivot: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], effects: collections.abc.Sequence[str] = [], effect_params: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex] = []) -> None:
        ...
    @property
    def effect_params(self) -> list[float]:
        ...
    @property
    def effects(self) -> list[str]:
        ...
    @property
    def errors(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def machine(self) -> MachineType:
        ...
    @property
    def pivot(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
class BallbarMonteCarlo:
    @property
    def draws(self) -> int:
        ...
    @property
    def fresh_fits(self) -> int:
        ...
    @property
    def noise(self) -> str:
        ...
    @property
    def noise_um(self) -> float:
        ...
    @property
    def parameters(self) -> list[MonteCarloParameter]:
        ...
    @property
    def values(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
class BallbarPlan:
    """
    Planned toolpath; per-sample arrays in program order.
    """
    def commanded_session(self) -> BallbarSession:
        """
        The test samples as a BallbarSession (length = L0), e.g. for simulate_ballbar.
        """
    @property
    def angles_deg(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 2]"]:
        """
        (N, 2) tilt (A or B) and C, deg
        """
    @property
    def compensation(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[8, 1]"] | None:
        """
        (8,) location errors the machine axes were computed with, or None (nominal)
        """
    @property
    def duration(self) -> float:
        """
        s
        """
    @property
    def labels(self) -> list[str]:
        """
        segment label per sample ('transition' between tests)
        """
    @property
    def machine_axes(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 5]"]:
        """
        (N, 5) X, Y, Z (mm), tilt, C (deg)
        """
    @property
    def num_samples(self) -> int:
        ...
    @property
    def p_table(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]:
        """
        (N, 3) tool-cup ball centre, table frame, mm
        """
    @property
    def segment_index(self) -> list[int]:
        ...
    @property
    def segments(self) -> list[PlanSegment]:
        ...
    @property
    def setup(self) -> BallbarSetup:
        ...
    @property
    def time(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        (N,) s
        """
class BallbarSession:
    """
    A rotacal-ballbar/1 session (mm, deg, s).
    """
    def __init__(self, machine: MachineType, ballbar_length: typing.SupportsFloat | typing.SupportsIndex, pivot: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"], tests: collections.abc.Sequence[str], time: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], xyz: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 3]"], angles_deg: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 2]"], length: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], noise_um: typing.SupportsFloat | typing.SupportsIndex | None = None) -> None:
        """
        Build a session from columns: tests (N labels), time (N,), xyz (N,3) tool cup, angles_deg (N,2) tilt and C, length (N,) measured lengths.
        """
    def __len__(self) -> int:
        ...
    def __repr__(self) -> str:
        ...
    def with_lengths(self, length: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> BallbarSession:
        """
        The same session with other lengths (e.g. a model's prediction).
        """
    @property
    def angles_deg(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 2]"]:
        ...
    @property
    def annotations(self) -> list[tuple[int, str]]:
        ...
    @property
    def ballbar_length(self) -> float:
        ...
    @property
    def length(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def machine(self) -> MachineType:
        ...
    @property
    def metadata(self) -> dict:
        ...
    @property
    def noise_um(self) -> float | None:
        ...
    @property
    def pivot(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def test_names(self) -> list[str]:
        """
        distinct test labels, in order
        """
    @property
    def tests(self) -> list[str]:
        """
        test label of every sample
        """
    @property
    def time(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def warnings(self) -> list[str]:
        """
        what the reader found suspicious but kept
        """
    @property
    def xyz(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]:
        ...
class BallbarSetup:
    """
    Layout of the single set-up ballbar test (mm, deg, mm/min, deg/min).
    """
    machine: MachineType
    radial_c_side: RadialSide
    def __init__(self, machine: MachineType = ..., ballbar_length: typing.SupportsFloat | typing.SupportsIndex = 100.0, pivot: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"] = ..., tilt_range_deg: typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(2)"] | None = None, rot_range_deg: typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(2)"] = [0.0, 360.0], step_deg: typing.SupportsFloat | typing.SupportsIndex = 1.0, feed_mm_per_min: typing.SupportsFloat | typing.SupportsIndex = 1000.0, feed_deg_per_min: typing.SupportsFloat | typing.SupportsIndex = 3600.0, tests: collections.abc.Sequence[BallbarTest] = ..., radial_c_side: RadialSide = RadialSide.outside, axial_c_tilt_deg: typing.SupportsFloat | typing.SupportsIndex | None = None, directions: collections.abc.Sequence[SweepDirection] = ..., feed_factors: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex] = [1.0]) -> None:
        """
        tilt_range_deg None: default_tilt_range_deg(machine); axial_c_tilt_deg None: default_axial_c_tilt_deg(machine).
        """
    @property
    def axial_c_tilt_deg(self) -> float | None:
        """
        tilt held during axial_c, deg; None: default_axial_c_tilt_deg(machine)
        """
    @axial_c_tilt_deg.setter
    def axial_c_tilt_deg(self, arg0: typing.SupportsFloat | typing.SupportsIndex | None) -> None:
        ...
    @property
    def ballbar_length(self) -> float:
        """
        L0, mm
        """
    @ballbar_length.setter
    def ballbar_length(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def directions(self) -> list[SweepDirection]:
        """
        directions of every rotary test, in order
        """
    @directions.setter
    def directions(self, arg0: collections.abc.Sequence[SweepDirection]) -> None:
        ...
    @property
    def feed_deg_per_min(self) -> float:
        ...
    @feed_deg_per_min.setter
    def feed_deg_per_min(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def feed_factors(self) -> list[float]:
        """
        feeds of every rotary test as factors of the set-up's feeds; the first is 1
        """
    @feed_factors.setter
    def feed_factors(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def feed_mm_per_min(self) -> float:
        ...
    @feed_mm_per_min.setter
    def feed_mm_per_min(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def pivot(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        nominal pivot ball centre, table frame, mm
        """
    @pivot.setter
    def pivot(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def rot_range_deg(self) -> typing.Annotated[list[float], "FixedSize(2)"]:
        """
        C sweep, deg; a 360 deg span is a full turn without its repeated end
        """
    @rot_range_deg.setter
    def rot_range_deg(self, arg0: typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(2)"]) -> None:
        ...
    @property
    def step_deg(self) -> float:
        ...
    @step_deg.setter
    def step_deg(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def tests(self) -> list[BallbarTest]:
        ...
    @tests.setter
    def tests(self, arg0: collections.abc.Sequence[BallbarTest]) -> None:
        ...
    @property
    def tilt_range_deg(self) -> typing.Annotated[list[float], "FixedSize(2)"]:
        ...
    @tilt_range_deg.setter
    def tilt_range_deg(self, arg0: typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(2)"]) -> None:
        ...
class BallbarTest:
    """
    Tests of the single set-up method; ``*_tilt`` are A or B by machine.
    
    Members:
    
      sphere_xy
    
      sphere_yz
    
      sphere_zx
    
      radial_tilt
    
      axial_tilt
    
      radial_c
    
      axial_c
    
      tangential_tilt
    
      tangential_c
    """
    __members__: typing.ClassVar[dict[str, BallbarTest]]  # value = {'sphere_xy': <BallbarTest.sphere_xy: 0>, 'sphere_yz': <BallbarTest.sphere_yz: 1>, 'sphere_zx': <BallbarTest.sphere_zx: 2>, 'radial_tilt': <BallbarTest.radial_tilt: 3>, 'axial_tilt': <BallbarTest.axial_tilt: 4>, 'radial_c': <BallbarTest.radial_c: 5>, 'axial_c': <BallbarTest.axial_c: 6>, 'tangential_tilt': <BallbarTest.tangential_tilt: 7>, 'tangential_c': <BallbarTest.tangential_c: 8>}
    axial_c: typing.ClassVar[BallbarTest]  # value = <BallbarTest.axial_c: 6>
    axial_tilt: typing.ClassVar[BallbarTest]  # value = <BallbarTest.axial_tilt: 4>
    radial_c: typing.ClassVar[BallbarTest]  # value = <BallbarTest.radial_c: 5>
    radial_tilt: typing.ClassVar[BallbarTest]  # value = <BallbarTest.radial_tilt: 3>
    sphere_xy: typing.ClassVar[BallbarTest]  # value = <BallbarTest.sphere_xy: 0>
    sphere_yz: typing.ClassVar[BallbarTest]  # value = <BallbarTest.sphere_yz: 1>
    sphere_zx: typing.ClassVar[BallbarTest]  # value = <BallbarTest.sphere_zx: 2>
    tangential_c: typing.ClassVar[BallbarTest]  # value = <BallbarTest.tangential_c: 8>
    tangential_tilt: typing.ClassVar[BallbarTest]  # value = <BallbarTest.tangential_tilt: 7>
    @typing.overload
    def __eq__(self, other: BallbarTest) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: BallbarTest) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class BudgetLine:
    @property
    def basis(self) -> str:
        ...
    @property
    def bias_at_size(self) -> float:
        ...
    @property
    def dof(self) -> float:
        ...
    @property
    def effect(self) -> str:
        ...
    @property
    def half_width(self) -> list[float]:
        ...
    @property
    def u(self) -> float:
        ...
class CandidateScore:
    @property
    def delta_bic(self) -> float:
        ...
    @property
    def effect(self) -> str:
        ...
    @property
    def f_pvalue(self) -> float:
        ...
    @property
    def rms_after_um(self) -> float:
        ...
    @property
    def visible_params(self) -> int:
        ...
class CircleFit:
    @property
    def centre(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 1]"]:
        ...
    @property
    def covariance(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 3]"]:
        """
        (cx, cy, r), 1-sigma^2
        """
    @property
    def n(self) -> int:
        ...
    @property
    def radius(self) -> float:
        ...
    @property
    def rms(self) -> float:
        ...
class CircularAnalysis:
    @property
    def ballbar_length(self) -> float:
        ...
    @property
    def ignored_tests(self) -> list[str]:
        ...
    @property
    def pairs(self) -> list[CircularPairResult]:
        ...
    @property
    def runs(self) -> list[CircularRunResult]:
        ...
class CircularDiagnosis:
    @property
    def baseline_rms_um(self) -> float:
        ...
    @property
    def final_rms_um(self) -> float:
        ...
    @property
    def findings(self) -> list[CircularFinding]:
        ...
    @property
    def first_round(self) -> list[CandidateScore]:
        ...
    @property
    def n(self) -> int:
        ...
    @property
    def noise(self) -> NoiseModel:
        ...
    @property
    def noise_whitened(self) -> bool:
        ...
    @property
    def residuals_mm(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def unobservable(self) -> list[UnobservableEffect]:
        ...
class CircularDiagnosisOptions:
    model_noise: bool
    def __init__(self) -> None:
        ...
    @property
    def alpha(self) -> float:
        ...
    @alpha.setter
    def alpha(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def cv_blocks(self) -> int:
        ...
    @cv_blocks.setter
    def cv_blocks(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def max_findings(self) -> int:
        ...
    @max_findings.setter
    def max_findings(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def min_delta_bic(self) -> float:
        ...
    @min_delta_bic.setter
    def min_delta_bic(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def min_visible_chi2(self) -> float:
        ...
    @min_visible_chi2.setter
    def min_visible_chi2(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def only(self) -> list[str]:
        ...
    @only.setter
    def only(self, arg0: collections.abc.Sequence[str]) -> None:
        ...
    @property
    def screw_pitch(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @screw_pitch.setter
    def screw_pitch(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
class CircularDirection:
    """
    ccw: G3, the path angle increases; cw: G2.
    
    Members:
    
      ccw
    
      cw
    """
    __members__: typing.ClassVar[dict[str, CircularDirection]]  # value = {'ccw': <CircularDirection.ccw: 0>, 'cw': <CircularDirection.cw: 1>}
    ccw: typing.ClassVar[CircularDirection]  # value = <CircularDirection.ccw: 0>
    cw: typing.ClassVar[CircularDirection]  # value = <CircularDirection.cw: 1>
    @typing.overload
    def __eq__(self, other: CircularDirection) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: CircularDirection) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class CircularEffect:
    """
    An entry of the circular-test catalogue.
    """
    def __init__(self, id: str) -> None:
        ...
    @property
    def cause(self) -> str:
        ...
    @property
    def id(self) -> str:
        ...
    @property
    def param_names(self) -> list[str]:
        ...
    @property
    def param_units(self) -> list[str]:
        ...
class CircularFinding:
    @property
    def cause(self) -> str:
        ...
    @property
    def effect(self) -> str:
        ...
    @property
    def gain(self) -> Gain:
        ...
    @property
    def parameters(self) -> list[ParameterEstimate]:
        ...
class CircularPairResult:
    @property
    def G_b_um(self) -> float:
        ...
    @property
    def H_angle_deg(self) -> float:
        ...
    @property
    def H_um(self) -> float:
        ...
    @property
    def ccw_label(self) -> str:
        ...
    @property
    def common_span_deg(self) -> float:
        ...
    @property
    def cw_label(self) -> str:
        ...
    @property
    def feed_mm_per_min(self) -> float:
        ...
    @property
    def plane(self) -> CircularPlane:
        ...
class CircularPlanResult:
    def num_samples(self) -> int:
        ...
    @property
    def plan(self) -> CircularTestPlan:
        ...
    @property
    def runs(self) -> list[CircularRun]:
        ...
class CircularPlane:
    """
    Plane of an ISO 230-4 circular test: (u, v) = XY, YZ, ZX.
    
    Members:
    
      XY
    
      YZ
    
      ZX
    """
    XY: typing.ClassVar[CircularPlane]  # value = <CircularPlane.XY: 0>
    YZ: typing.ClassVar[CircularPlane]  # value = <CircularPlane.YZ: 1>
    ZX: typing.ClassVar[CircularPlane]  # value = <CircularPlane.ZX: 2>
    __members__: typing.ClassVar[dict[str, CircularPlane]]  # value = {'XY': <CircularPlane.XY: 0>, 'YZ': <CircularPlane.YZ: 1>, 'ZX': <CircularPlane.ZX: 2>}
    @typing.overload
    def __eq__(self, other: CircularPlane) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: CircularPlane) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class CircularRun:
    @property
    def angle_deg(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def data_from_deg(self) -> float:
        ...
    @property
    def data_to_deg(self) -> float:
        ...
    @property
    def direction(self) -> CircularDirection:
        ...
    @property
    def feed_mm_per_min(self) -> float:
        ...
    @property
    def label(self) -> str:
        ...
    @property
    def overshoot_to_deg(self) -> float:
        ...
    @property
    def plane(self) -> CircularPlane:
        ...
    @property
    def run_in_from_deg(self) -> float:
        ...
    @property
    def t_start(self) -> float:
        ...
    @property
    def time(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
class CircularRunResult:
    @property
    def G_um(self) -> float:
        ...
    @property
    def angle_deg(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def centre_um(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 1]"]:
        ...
    @property
    def direction(self) -> CircularDirection:
        ...
    @property
    def feed_mm_per_min(self) -> float:
        ...
    @property
    def label(self) -> str:
        ...
    @property
    def max_um(self) -> float:
        ...
    @property
    def min_um(self) -> float:
        ...
    @property
    def n(self) -> int:
        ...
    @property
    def plane(self) -> CircularPlane:
        ...
    @property
    def radial_um(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def radius_deviation_um(self) -> float:
        ...
    @property
    def span_deg(self) -> float:
        ...
class CircularSimulationOptions:
    errors: LinearAxisErrors
    def __init__(self) -> None:
        ...
    @property
    def centring_error(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @centring_error.setter
    def centring_error(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def length_error(self) -> float:
        ...
    @length_error.setter
    def length_error(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def noise_rho(self) -> float:
        ...
    @noise_rho.setter
    def noise_rho(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def noise_um(self) -> float:
        ...
    @noise_um.setter
    def noise_um(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def seed(self) -> int:
        ...
    @seed.setter
    def seed(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
class CircularTestPlan:
    """
    ISO 230-4 circular tests with the ballbar (mm, deg, mm/min, Hz, s).
    """
    machine: MachineType
    def __init__(self, machine: MachineType = ..., radius: typing.SupportsFloat | typing.SupportsIndex = 100.0, centre: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"] = ..., planes: collections.abc.Sequence[CircularPlane] = ..., feeds_mm_per_min: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex] = [1000.0, 3000.0], directions: collections.abc.Sequence[CircularDirection] = ..., start_deg: typing.SupportsFloat | typing.SupportsIndex = 0.0, span_deg: typing.SupportsFloat | typing.SupportsIndex = 360.0, run_in_deg: typing.SupportsFloat | typing.SupportsIndex = 45.0, overshoot_deg: typing.SupportsFloat | typing.SupportsIndex = 45.0, sample_rate_hz: typing.SupportsFloat | typing.SupportsIndex = 250.0, remount_s: typing.SupportsFloat | typing.SupportsIndex = 30.0) -> None:
        ...
    @property
    def centre(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @centre.setter
    def centre(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def directions(self) -> list[CircularDirection]:
        ...
    @directions.setter
    def directions(self, arg0: collections.abc.Sequence[CircularDirection]) -> None:
        ...
    @property
    def feeds_mm_per_min(self) -> list[float]:
        ...
    @feeds_mm_per_min.setter
    def feeds_mm_per_min(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def overshoot_deg(self) -> float:
        ...
    @overshoot_deg.setter
    def overshoot_deg(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def planes(self) -> list[CircularPlane]:
        ...
    @planes.setter
    def planes(self, arg0: collections.abc.Sequence[CircularPlane]) -> None:
        ...
    @property
    def radius(self) -> float:
        ...
    @radius.setter
    def radius(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def remount_s(self) -> float:
        ...
    @remount_s.setter
    def remount_s(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def run_in_deg(self) -> float:
        ...
    @run_in_deg.setter
    def run_in_deg(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def sample_rate_hz(self) -> float:
        ...
    @sample_rate_hz.setter
    def sample_rate_hz(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def span_deg(self) -> float:
        ...
    @span_deg.setter
    def span_deg(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def start_deg(self) -> float:
        ...
    @start_deg.setter
    def start_deg(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class CompensationReport:
    @property
    def after(self) -> BallbarIdentification:
        ...
    @property
    def before(self) -> BallbarIdentification:
        ...
    @property
    def rows(self) -> list[CompensationRow]:
        ...
class CompensationRow:
    @property
    def after(self) -> float:
        ...
    @property
    def before(self) -> float:
        ...
    @property
    def change_percent(self) -> float:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def std_after(self) -> float:
        ...
    @property
    def unit(self) -> str:
        ...
class CompensationTable:
    """
    One joint's compensation table.
    """
    @property
    def axis(self) -> str:
        ...
    @property
    def file_name(self) -> str:
        ...
    @property
    def holds(self) -> list[str]:
        """
        the model's terms the table holds (a residual model zeroes them)
        """
    @property
    def joint(self) -> int:
        ...
    @property
    def max_interpolation_error_deg(self) -> float:
        ...
    @property
    def max_interpolation_error_mm(self) -> float:
        ...
    @property
    def nominal_deg(self) -> list[float]:
        ...
    @property
    def summary(self) -> str:
        ...
    @property
    def text(self) -> str:
        ...
    @property
    def value_deg(self) -> list[float]:
        """
        the values written, deg
        """
    @property
    def value_mm(self) -> dict[str, list[float]]:
        """
        a cross table: the correction of each output axis X, Y, Z at nominal_deg, mm
        """
class CompensationTables:
    """
    A controller's tables of a model.
    """
    @property
    def ini(self) -> str:
        """
        the INI lines that load them
        """
    @property
    def not_held(self) -> list[str]:
        ...
    @property
    def tables(self) -> list[CompensationTable]:
        ...
class ControllerExport:
    """
    A model's location errors in a controller's parameters.
    """
    @property
    def controller(self) -> str:
        ...
    @property
    def current_given(self) -> bool:
        ...
    @property
    def errors(self) -> list[ErrorDisposition]:
        ...
    @property
    def file_kind(self) -> str:
        ...
    @property
    def kinematics(self) -> str:
        ...
    @property
    def not_held(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        (8,) errors the controller cannot hold (mm, rad): NC compensation
        """
    @property
    def text(self) -> str:
        """
        the file to load on the controller
        """
    @property
    def values(self) -> list[ControllerValue]:
        ...
class ControllerValue:
    """
    One controller parameter as written.
    """
    @property
    def corrected(self) -> float:
        ...
    @property
    def current(self) -> float:
        """
        active while the test ran (0 when not given)
        """
    @property
    def name(self) -> str:
        ...
    @property
    def source(self) -> str:
        """
        the location errors it carries
        """
    @property
    def std(self) -> float:
        """
        1 sigma of corrected, controller units
        """
    @property
    def unit(self) -> str:
        ...
class DegenerateGeometry(Error):
    pass
class DesignCandidate:
    """
    One set-up, evaluated.
    """
    @property
    def duration_s(self) -> float:
        ...
    @property
    def effect_vs_effects(self) -> list[float]:
        ...
    @property
    def effect_vs_location(self) -> list[float]:
        ...
    @property
    def feasible(self) -> bool:
        ...
    @property
    def names(self) -> list[str]:
        ...
    @property
    def setup(self) -> BallbarSetup:
        ...
    @property
    def sigma(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        predicted 1 sigma at the time budget (mm, rad)
        """
    @property
    def why_not(self) -> str:
        ...
    @property
    def worst_error(self) -> str:
        ...
    @property
    def worst_expanded_um(self) -> float:
        ...
class DeviceDisconnected(SerialError):
    pass
class Diagnosis:
    @property
    def ambiguous(self) -> list[Ambiguity]:
        ...
    @property
    def angle_tables(self) -> list[AngleTable]:
        ...
    @property
    def baseline(self) -> DiagnosisBaseline:
        ...
    @property
    def baseline_fit(self) -> ModelFit:
        ...
    @property
    def final_fit(self) -> ModelFit:
        ...
    @property
    def findings(self) -> list[Finding]:
        ...
    @property
    def machine(self) -> MachineType:
        ...
    @property
    def noise(self) -> NoiseModel:
        ...
    @property
    def noise_whitened(self) -> bool:
        ...
    @property
    def rounds(self) -> list[list[CandidateScore]]:
        ...
    @property
    def seconds(self) -> float:
        ...
    @property
    def structure_after(self) -> list[GroupResidual]:
        ...
    @property
    def structure_before(self) -> list[GroupResidual]:
        ...
    @property
    def unexplained(self) -> Unexplained:
        ...
    @property
    def unobservable(self) -> list[UnobservableEffect]:
        ...
class DiagnosisBaseline:
    @property
    def chi2_per_dof(self) -> float:
        ...
    @property
    def dof(self) -> int:
        ...
    @property
    def n(self) -> int:
        ...
    @property
    def noise_source(self) -> str:
        ...
    @property
    def noise_um(self) -> float:
        ...
    @property
    def p_value(self) -> float:
        ...
    @property
    def residual_rms_um(self) -> float:
        ...
class DiagnosisOptions:
    hold_by_weight: bool
    model_noise: bool
    def __init__(self) -> None:
        ...
    @property
    def alpha(self) -> float:
        ...
    @alpha.setter
    def alpha(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def cv_blocks(self) -> int:
        ...
    @cv_blocks.setter
    def cv_blocks(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def max_findings(self) -> int:
        ...
    @max_findings.setter
    def max_findings(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def max_harmonic(self) -> int:
        ...
    @max_harmonic.setter
    def max_harmonic(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def min_delta_bic(self) -> float:
        ...
    @min_delta_bic.setter
    def min_delta_bic(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def min_determined_sigma(self) -> float:
        ...
    @min_determined_sigma.setter
    def min_determined_sigma(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def min_weight(self) -> float:
        ...
    @min_weight.setter
    def min_weight(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def only(self) -> list[str]:
        ...
    @only.setter
    def only(self, arg0: collections.abc.Sequence[str]) -> None:
        ...
    @property
    def progress(self) -> collections.abc.Callable[[str, typing.SupportsInt | typing.SupportsIndex, typing.SupportsInt | typing.SupportsIndex], None]:
        """
        callable(stage, done, total) after each scored candidate, or None
        """
    @progress.setter
    def progress(self, arg0: collections.abc.Callable[[str, int, int], None]) -> None:
        ...
    @property
    def rival_correlation(self) -> float:
        ...
    @rival_correlation.setter
    def rival_correlation(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class Effect:
    """
    One entry of the effects catalogue (shared/spec/effects.md).
    """
    __hash__: typing.ClassVar[None] = None
    def __eq__(self, arg0: Effect) -> bool:
        ...
    def __init__(self, id: str) -> None:
        """
        Parse a catalogue id such as 'coning_B'.
        """
    def __repr__(self) -> str:
        ...
    def applies_to(self, machine: MachineType) -> bool:
        ...
    @property
    def cause(self) -> str:
        ...
    @property
    def harmonic(self) -> int:
        ...
    @property
    def id(self) -> str:
        ...
    @property
    def num_params(self) -> int:
        ...
    @property
    def param_names(self) -> list[str]:
        ...
    @property
    def param_units(self) -> list[str]:
        ...
class Error(RuntimeError):
    pass
class ErrorDisposition:
    """
    Whether a location error reaches the controller.
    """
    @property
    def held(self) -> bool:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def observable(self) -> bool:
        ...
    @property
    def std(self) -> float:
        ...
    @property
    def value(self) -> float:
        ...
    @property
    def where(self) -> str:
        ...
class FanucPitchOptions:
    """
    FANUC pitch error compensation: the control's units and limits.
    """
    def __init__(self) -> None:
        ...
    @property
    def detection_unit_deg(self) -> float:
        ...
    @detection_unit_deg.setter
    def detection_unit_deg(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def first_number(self) -> int:
        ...
    @first_number.setter
    def first_number(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def last_number(self) -> int:
        ...
    @last_number.setter
    def last_number(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def magnification(self) -> int:
        """
        parameter 3623; 0: the smallest of 1..100 that keeps the values in range
        """
    @magnification.setter
    def magnification(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def max_value(self) -> int:
        ...
    @max_value.setter
    def max_value(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
class FaultInjection:
    """
    Faults a virtual instrument acts out (counted in frames).
    """
    split_frames: bool
    def __init__(self) -> None:
        ...
    @property
    def close_after(self) -> int:
        ...
    @close_after.setter
    def close_after(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def corrupt_every(self) -> int:
        ...
    @corrupt_every.setter
    def corrupt_every(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def drop_every(self) -> int:
        ...
    @drop_every.setter
    def drop_every(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def garbage_every(self) -> int:
        ...
    @garbage_every.setter
    def garbage_every(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def silence_after(self) -> int:
        ...
    @silence_after.setter
    def silence_after(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
class Finding:
    @property
    def cause(self) -> str:
        ...
    @property
    def effect(self) -> str:
        ...
    @property
    def gain(self) -> Gain:
        ...
    @property
    def lack_of_fit(self) -> str:
        ...
    @property
    def model_reason(self) -> str:
        ...
    @property
    def named_alone(self) -> bool:
        ...
    @property
    def parameters(self) -> list[ParameterEstimate]:
        ...
    @property
    def rivals(self) -> list[Alternative]:
        ...
    @property
    def shifts(self) -> list[ParameterShift]:
        ...
    @property
    def weight(self) -> float:
        ...
class FitSummary:
    """
    How a least-squares solve went (core/estimate.hpp).
    """
    @property
    def chi2(self) -> float:
        ...
    @property
    def chi2_per_dof(self) -> float:
        ...
    @property
    def converged(self) -> bool:
        ...
    @property
    def iterations(self) -> int:
        ...
    @property
    def jacobian_evaluations(self) -> int:
        ...
    @property
    def message(self) -> str:
        ...
    @property
    def num_free(self) -> int:
        ...
    @property
    def num_residuals(self) -> int:
        ...
    @property
    def residual_evaluations(self) -> int:
        ...
    @property
    def whitened(self) -> bool:
        ...
class Gain:
    @property
    def cv_rms_after_um(self) -> float:
        ...
    @property
    def cv_rms_before_um(self) -> float:
        ...
    @property
    def delta_bic(self) -> float:
        ...
    @property
    def f_pvalue(self) -> float:
        ...
    @property
    def rms_after_um(self) -> float:
        ...
    @property
    def rms_before_um(self) -> float:
        ...
class GroupResidual:
    @property
    def angle_axis(self) -> str:
        ...
    @property
    def group(self) -> str:
        ...
    @property
    def harmonic_note(self) -> str:
        ...
    @property
    def harmonic_um(self) -> list[float]:
        ...
    @property
    def harmonics_left_out(self) -> list[int]:
        ...
    @property
    def mean_um(self) -> float:
        ...
    @property
    def n(self) -> int:
        ...
    @property
    def rms_um(self) -> float:
        ...
    @property
    def trend_um_per_s(self) -> float:
        ...
class Identification:
    """
    What an identification reports, whatever the instrument (core/identification.hpp); the instrument's parts (pivot, zeros, sphere, effects) are named blocks of `parameters`.
    """
    def block(self, name: str) -> list[ParameterEstimate]:
        """
        The estimates of the named parameter block (e.g. 'pivot', 'sphere', 'zeros').
        """
    def parameter(self, name: str) -> ParameterEstimate:
        """
        The estimate called `name`.
        """
    @property
    def block_names(self) -> list[str]:
        ...
    @property
    def converged(self) -> bool:
        ...
    @property
    def covariance(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    @property
    def iterations(self) -> int:
        ...
    @property
    def method(self) -> str:
        ...
    @property
    def n_samples(self) -> int:
        ...
    @property
    def noise(self) -> ...:
        ...
    @property
    def noise_correction(self) -> float:
        ...
    @property
    def noise_refit(self) -> bool:
        ...
    @property
    def notes(self) -> list[str]:
        ...
    @property
    def parameters(self) -> list[ParameterEstimate]:
        ...
    @property
    def residual_rms_um(self) -> float:
        ...
    @property
    def residuals(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def sigma_um(self) -> float:
        ...
    @property
    def summary(self) -> FitSummary:
        ...
    @property
    def unobservable(self) -> list[str]:
        ...
class InvalidArgument(Error):
    pass
class IoError(Error):
    pass
class LinearAxisErrors:
    """
    Errors of the linear axes X, Y, Z (mm, rad, s); see circular/simulate.hpp.
    """
    def __init__(self) -> None:
        ...
    @property
    def backlash(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @backlash.setter
    def backlash(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def cyclic_cos(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @cyclic_cos.setter
    def cyclic_cos(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def cyclic_sin(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @cyclic_sin.setter
    def cyclic_sin(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def scale(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @scale.setter
    def scale(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def screw_pitch(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @screw_pitch.setter
    def screw_pitch(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def servo_tau(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @servo_tau.setter
    def servo_tau(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def spike(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @spike.setter
    def spike(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def spike_tau(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @spike_tau.setter
    def spike_tau(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def squareness(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @squareness.setter
    def squareness(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def straightness(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 3]"]:
        ...
    @straightness.setter
    def straightness(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 3]"]) -> None:
        ...
class LocationBudget:
    @property
    def dof_a(self) -> float:
        ...
    @property
    def dominant(self) -> list[str]:
        ...
    @property
    def expanded(self) -> float:
        ...
    @property
    def k(self) -> float:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def nu_eff(self) -> float:
        ...
    @property
    def observable(self) -> bool:
        ...
    @property
    def type_b(self) -> list[BudgetLine]:
        ...
    @property
    def u_a(self) -> float:
        ...
    @property
    def u_c(self) -> float:
        ...
    @property
    def unit(self) -> str:
        ...
    @property
    def value(self) -> float:
        ...
class MachineType:
    """
    A 5-axis machine: a built-in (AC_trt, BC_trt, builtin(name)) or a rotacal-machine/1 description (from_description).
    """
    AC_trt: typing.ClassVar[MachineType]  # value = MachineType.AC_trt
    BC_trt: typing.ClassVar[MachineType]  # value = MachineType.BC_trt
    @staticmethod
    def from_description(json_text: str, source: str = 'machine description') -> MachineType:
        """
        The machine of a rotacal-machine/1 JSON text; errors name `source` and the field.
        """
    def __eq__(self, arg0: MachineType) -> bool:
        ...
    def __getstate__(self) -> str:
        ...
    def __hash__(self) -> int:
        ...
    def __ne__(self, arg0: MachineType) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, arg0: str) -> None:
        ...
    @property
    def axis_names(self) -> str:
        """
        Rotary axis letters in chain order (table axes, then head axes): the session's rotary columns.
        """
    @property
    def configuration(self) -> str:
        ...
    @property
    def description_json(self) -> str:
        ...
    @property
    def has_head(self) -> bool:
        ...
    @property
    def is_builtin(self) -> bool:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def rot_axis(self) -> str:
        ...
    @property
    def tilt_axis(self) -> str:
        ...
class ModelFit:
    @property
    def effects(self) -> list[str]:
        ...
    @property
    def num_free(self) -> int:
        ...
    @property
    def parameters(self) -> list[ParameterEstimate]:
        ...
    @property
    def residuals(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
class MonteCarloParameter:
    @property
    def bias(self) -> float:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def ratio(self) -> float:
        ...
    @property
    def std_mc(self) -> float:
        ...
    @property
    def std_reported(self) -> float:
        ...
    @property
    def unit(self) -> str:
        ...
class MultiDiagnosis:
    @property
    def diagnosis(self) -> Diagnosis:
        ...
    @property
    def notes(self) -> list[str]:
        ...
    @property
    def sessions(self) -> list[MultiDiagnosisSession]:
        ...
    @property
    def where(self) -> list[str]:
        ...
class MultiDiagnosisSession:
    @property
    def instrument(self) -> str:
        ...
    @property
    def n(self) -> int:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def noise_um(self) -> float:
        ...
    @property
    def rms_after_um(self) -> float:
        ...
    @property
    def rms_before_um(self) -> float:
        ...
    @property
    def weight(self) -> float:
        ...
class MultiDisagreement:
    @property
    def difference(self) -> float:
        ...
    @property
    def dof(self) -> float:
        """
        of sigma (Welch-Satterthwaite)
        """
    @property
    def parameter(self) -> str:
        ...
    @property
    def session_a(self) -> str:
        ...
    @property
    def session_b(self) -> str:
        ...
    @property
    def sigma(self) -> float:
        ...
    @property
    def threshold(self) -> float:
        """
        abs(z) beyond which it disagrees
        """
    @property
    def unit(self) -> str:
        ...
    @property
    def value_a(self) -> float:
        ...
    @property
    def value_b(self) -> float:
        ...
    @property
    def z(self) -> float:
        ...
class MultiIdentification(Identification):
    """
    The joint identification: blocks 'location_errors', 'effects', then one per session.
    """
    @property
    def comparisons(self) -> int:
        ...
    @property
    def disagreement_z(self) -> float:
        ...
    @property
    def disagreements(self) -> list[MultiDisagreement]:
        ...
    @property
    def effects(self) -> list[ParameterEstimate]:
        ...
    @property
    def location_errors(self) -> list[ParameterEstimate]:
        ...
    @property
    def machine(self) -> MachineType:
        ...
    @property
    def sessions(self) -> list[MultiSessionResult]:
        ...
    @property
    def sigma_inflated(self) -> bool:
        ...
class MultiSessionResult:
    @property
    def alone(self) -> list[ParameterEstimate]:
        ...
    @property
    def dof(self) -> float:
        """
        of its sigmas alone
        """
    @property
    def instrument(self) -> str:
        ...
    @property
    def n_residuals(self) -> int:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def noise(self) -> NoiseModel:
        ...
    @property
    def noise_correction(self) -> float:
        ...
    @property
    def noise_refit(self) -> bool:
        ...
    @property
    def nuisances(self) -> list[ParameterEstimate]:
        ...
    @property
    def residual_rms_um(self) -> float:
        ...
class NcDialect:
    """
    Members:
    
      linuxcnc
    
      heidenhain
    
      siemens
    
      fanuc
    """
    __members__: typing.ClassVar[dict[str, NcDialect]]  # value = {'linuxcnc': <NcDialect.linuxcnc: 0>, 'heidenhain': <NcDialect.heidenhain: 1>, 'siemens': <NcDialect.siemens: 2>, 'fanuc': <NcDialect.fanuc: 3>}
    fanuc: typing.ClassVar[NcDialect]  # value = <NcDialect.fanuc: 3>
    heidenhain: typing.ClassVar[NcDialect]  # value = <NcDialect.heidenhain: 1>
    linuxcnc: typing.ClassVar[NcDialect]  # value = <NcDialect.linuxcnc: 0>
    siemens: typing.ClassVar[NcDialect]  # value = <NcDialect.siemens: 2>
    @typing.overload
    def __eq__(self, other: NcDialect) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: NcDialect) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class NcProgramOptions:
    program_name: str
    stop_to_mount: bool
    def __init__(self, decimals: typing.SupportsInt | typing.SupportsIndex = 4, tool: typing.SupportsInt | typing.SupportsIndex = 1, stop_to_mount: bool = True, program_name: str = 'ROTACAL_BALLBAR', program_number: typing.SupportsInt | typing.SupportsIndex = 1000) -> None:
        ...
    @property
    def decimals(self) -> int:
        ...
    @decimals.setter
    def decimals(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def program_number(self) -> int:
        ...
    @program_number.setter
    def program_number(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def tool(self) -> int:
        ...
    @tool.setter
    def tool(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
class NoiseModel:
    def summary(self) -> str:
        ...
    def whiten(self, columns: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], residual_unit_mm: typing.SupportsFloat | typing.SupportsIndex = 1.0) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        Whitened copy of `columns` (one row per reading): unit variance if the model holds.
        """
    @property
    def correlation_samples(self) -> float:
        ...
    @property
    def correlation_time_s(self) -> float:
        ...
    @property
    def effective_samples(self) -> float:
        ...
    @property
    def innovation_sigma_um(self) -> float:
        ...
    @property
    def max_order(self) -> int:
        ...
    @property
    def n(self) -> int:
        ...
    @property
    def random_walk_step_um(self) -> float:
        """
        largest random-walk step of any stream, um (0: none)
        """
    @property
    def sigma_um(self) -> float:
        ...
    @property
    def streams(self) -> list[NoiseStream]:
        ...
    @property
    def white(self) -> bool:
        ...
class NoiseModelOptions:
    pooled: bool
    def __init__(self) -> None:
        ...
    @property
    def max_order(self) -> int:
        ...
    @max_order.setter
    def max_order(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    @property
    def min_stream_size(self) -> int:
        ...
    @min_stream_size.setter
    def min_stream_size(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
class NoiseStream:
    @property
    def ar(self) -> list[float]:
        ...
    @property
    def channel(self) -> int:
        ...
    @property
    def correlation_samples(self) -> float:
        ...
    @property
    def correlation_time_s(self) -> float:
        ...
    @property
    def effective_samples(self) -> float:
        ...
    @property
    def group(self) -> str:
        ...
    @property
    def innovation_sigma_um(self) -> float:
        ...
    @property
    def marginal_sigma_um(self) -> float:
        ...
    @property
    def n(self) -> int:
        ...
    @property
    def random_walk_step_um(self) -> float:
        """
        1 sigma of the random-walk step per reading, um (0: none; R-test REML)
        """
    @property
    def reflection(self) -> list[float]:
        ...
    @property
    def sample_interval_s(self) -> float:
        ...
class ParameterEstimate:
    def __repr__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def observable(self) -> bool:
        ...
    @property
    def std(self) -> float:
        ...
    @property
    def unit(self) -> str:
        ...
    @property
    def value(self) -> float:
        ...
class ParameterShift:
    @property
    def after(self) -> float:
        ...
    @property
    def before(self) -> float:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def std_after(self) -> float:
        ...
    @property
    def unit(self) -> str:
        ...
class ParseError(Error):
    pass
class PlanSegment:
    @property
    def arc(self) -> TransitionArc:
        ...
    @property
    def direction(self) -> SweepDirection:
        ...
    @property
    def feed_factor(self) -> float:
        ...
    @property
    def kind(self) -> SegmentKind:
        ...
    @property
    def label(self) -> str:
        ...
    @property
    def num_samples(self) -> int:
        ...
    @property
    def test(self) -> rotacal._core.BallbarTest | None:
        ...
class PlaneFit:
    @property
    def centroid(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def n(self) -> int:
        ...
    @property
    def normal(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def normal_covariance(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 3]"]:
        ...
    @property
    def rms(self) -> float:
        ...
    @property
    def singular_values(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
class PlausibilityOptions:
    """
    Limits of the plausibility checks (mm, deg).
    """
    def __init__(self) -> None:
        ...
    @property
    def max_displacement_mm(self) -> float:
        ...
    @max_displacement_mm.setter
    def max_displacement_mm(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def max_length_deviation_mm(self) -> float:
        ...
    @max_length_deviation_mm.setter
    def max_length_deviation_mm(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def max_position_deviation_mm(self) -> float:
        ...
    @max_position_deviation_mm.setter
    def max_position_deviation_mm(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def min_ballbar_length_mm(self) -> float:
        ...
    @min_ballbar_length_mm.setter
    def min_ballbar_length_mm(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def min_rotary_span_deg(self) -> float:
        ...
    @min_rotary_span_deg.setter
    def min_rotary_span_deg(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class PlausibilityReport:
    @property
    def max_deviation_mm(self) -> float:
        ...
    @property
    def median_deviation_mm(self) -> float:
        ...
    @property
    def rot_span_deg(self) -> float:
        ...
    @property
    def tilt_span_deg(self) -> float:
        ...
    @property
    def worst_sample(self) -> int:
        ...
class PlausibleSizes:
    use_session_bounds: bool
    def __init__(self) -> None:
        ...
    @property
    def angular_error_rad(self) -> float:
        ...
    @angular_error_rad.setter
    def angular_error_rad(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def angular_positioning_rad(self) -> float:
        ...
    @angular_positioning_rad.setter
    def angular_positioning_rad(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def backlash_rad(self) -> float:
        ...
    @backlash_rad.setter
    def backlash_rad(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def bar_length_mm(self) -> float:
        ...
    @bar_length_mm.setter
    def bar_length_mm(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def coning(self) -> float:
        ...
    @coning.setter
    def coning(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def drift_mm(self) -> float:
        ...
    @drift_mm.setter
    def drift_mm(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def error_motion_mm(self) -> float:
        ...
    @error_motion_mm.setter
    def error_motion_mm(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def gravity_sag_mm(self) -> float:
        ...
    @gravity_sag_mm.setter
    def gravity_sag_mm(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def overrides(self) -> dict[str, float]:
        ...
    @overrides.setter
    def overrides(self, arg0: collections.abc.Mapping[str, typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def probe_lobing_mm(self) -> float:
        ...
    @probe_lobing_mm.setter
    def probe_lobing_mm(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def reversal_spike_rad(self) -> float:
        ...
    @reversal_spike_rad.setter
    def reversal_spike_rad(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def rotary_zero_rad(self) -> float:
        ...
    @rotary_zero_rad.setter
    def rotary_zero_rad(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def scale(self) -> float:
        ...
    @scale.setter
    def scale(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def servo_lag_s(self) -> float:
        ...
    @servo_lag_s.setter
    def servo_lag_s(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def squareness_rad(self) -> float:
        ...
    @squareness_rad.setter
    def squareness_rad(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def straightness_length_mm(self) -> float:
        ...
    @straightness_length_mm.setter
    def straightness_length_mm(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def straightness_mm(self) -> float:
        ...
    @straightness_mm.setter
    def straightness_mm(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def stylus_radius_mm(self) -> float:
        ...
    @stylus_radius_mm.setter
    def stylus_radius_mm(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def tilt_motion_rad(self) -> float:
        ...
    @tilt_motion_rad.setter
    def tilt_motion_rad(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def tool_length_mm(self) -> float:
        ...
    @tool_length_mm.setter
    def tool_length_mm(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def tool_offset_mm(self) -> float:
        ...
    @tool_offset_mm.setter
    def tool_offset_mm(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def warmup_mm(self) -> float:
        ...
    @warmup_mm.setter
    def warmup_mm(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class ProbeCalibration:
    """
    Probe directions from linear moves.
    """
    @property
    def direction_std_rad(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def dirs(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 3]"]:
        """
        unit directions (rows), table frame
        """
    @property
    def gain_std(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def gains(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def residual_rms_um(self) -> float:
        ...
    @property
    def residuals(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]:
        ...
    @property
    def sigma_um(self) -> float:
        ...
    @property
    def zeros(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        probe zero offsets, mm
        """
class ProbeDesign:
    """
    The designed poses and the default ones at the same touches.
    """
    @property
    def baseline(self) -> ProbeDesignCandidate:
        ...
    @property
    def best(self) -> ProbeDesignCandidate:
        ...
    @property
    def poses_tried(self) -> int:
        ...
    @property
    def ratio(self) -> float:
        ...
    @property
    def refused(self) -> list[str]:
        ...
    @property
    def sphere(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def spheres(self) -> list[ProbeSphereTrial]:
        ...
    @property
    def touches(self) -> int:
        ...
    @property
    def touches_tried(self) -> int:
        ...
class ProbeDesignCandidate:
    """
    Poses and touches, evaluated.
    """
    @property
    def directions(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]:
        ...
    @property
    def feasible(self) -> bool:
        ...
    @property
    def names(self) -> list[str]:
        ...
    @property
    def pose_directions(self) -> list[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]]:
        """
        each pose's own directions (K_i, 3); empty: `directions` at every pose
        """
    @property
    def poses_deg(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 2]"]:
        """
        pose visits (P, 2): tilt, rotary, deg, in program order
        """
    @property
    def sigma(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        predicted 1 sigma (mm, rad); inf: held
        """
    @property
    def sphere(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def touches(self) -> int:
        ...
    @property
    def undetermined(self) -> list[str]:
        ...
    @property
    def why_not(self) -> str:
        ...
    @property
    def worst_error(self) -> str:
        ...
    @property
    def worst_expanded_um(self) -> float:
        ...
class ProbeDesignOptions:
    """
    Options of design_probe_test (defaults).
    """
    machine: MachineType
    def __init__(self) -> None:
        ...
    @property
    def contact_step_deg(self) -> float:
        ...
    @contact_step_deg.setter
    def contact_step_deg(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def directions(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]:
        """
        approach directions (K, 3), machine frame; empty: the default pattern's
        """
    @directions.setter
    def directions(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> None:
        ...
    @property
    def max_contact_angle_deg(self) -> float:
        ...
    @max_contact_angle_deg.setter
    def max_contact_angle_deg(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def noise_um(self) -> float:
        ...
    @noise_um.setter
    def noise_um(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def reference_radius_mm(self) -> float:
        ...
    @reference_radius_mm.setter
    def reference_radius_mm(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def rot_step_deg(self) -> float:
        ...
    @rot_step_deg.setter
    def rot_step_deg(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def sphere(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        nominal centre, table frame, mm
        """
    @sphere.setter
    def sphere(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def sphere_candidates(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]:
        """
        other places of the sphere (S, 3), table frame, mm
        """
    @sphere_candidates.setter
    def sphere_candidates(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> None:
        ...
    @property
    def sphere_diameter(self) -> float:
        ...
    @sphere_diameter.setter
    def sphere_diameter(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def sphere_gain(self) -> float:
        ...
    @sphere_gain.setter
    def sphere_gain(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def stylus_diameter(self) -> float:
        ...
    @stylus_diameter.setter
    def stylus_diameter(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def tilt_step_deg(self) -> float:
        ...
    @tilt_step_deg.setter
    def tilt_step_deg(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def touch_directions(self) -> bool:
        """
        each touch its own direction
        """
    @touch_directions.setter
    def touch_directions(self, arg0: bool) -> None:
        ...
    @property
    def touches(self) -> int:
        """
        0: the default poses'
        """
    @touches.setter
    def touches(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
class ProbeIdentification(Identification):
    @property
    def dispersion_um(self) -> float:
        ...
    @property
    def effect_params(self) -> list[float]:
        ...
    @property
    def effects(self) -> list[str]:
        ...
    @property
    def errors(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def machine(self) -> MachineType:
        ...
    @property
    def pose_centres(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]:
        ...
    @property
    def pose_labels(self) -> list[str]:
        ...
    @property
    def sphere(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
class ProbeMonteCarlo:
    @property
    def draws(self) -> int:
        ...
    @property
    def noise(self) -> str:
        ...
    @property
    def noise_um(self) -> float:
        ...
    @property
    def parameters(self) -> list[MonteCarloParameter]:
        ...
    @property
    def values(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
class ProbeSeparatingCandidate:
    """
    Added poses, evaluated with the session.
    """
    @property
    def correlation(self) -> float:
        ...
    @property
    def description(self) -> str:
        ...
    @property
    def determined(self) -> bool:
        ...
    @property
    def directions(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]:
        ...
    @property
    def duration_s(self) -> float:
        ...
    @property
    def poses_deg(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 2]"]:
        ...
    @property
    def repeats(self) -> float:
        ...
class ProbeSeparationDesign:
    """
    The added poses that separate two effects, or why none can.
    """
    @property
    def already_separated(self) -> bool:
        ...
    @property
    def candidates_tried(self) -> int:
        ...
    @property
    def chosen(self) -> ProbeSeparatingCandidate:
        ...
    @property
    def correlation_before(self) -> float:
        ...
    @property
    def effective_per_reading(self) -> float:
        ...
    @property
    def effects(self) -> typing.Annotated[list[str], "FixedSize(2)"]:
        ...
    @property
    def found(self) -> bool:
        ...
    @property
    def motion(self) -> TableMotionOverlap:
        ...
    @property
    def names(self) -> list[str]:
        ...
    @property
    def noise_um(self) -> float:
        ...
    @property
    def sigma_after(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def sigma_before(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def verdict(self) -> str:
        ...
class ProbeSeparationOptions:
    """
    Options of design_probe_separation (defaults).
    """
    def __init__(self) -> None:
        ...
    @property
    def max_added_time_s(self) -> float:
        ...
    @max_added_time_s.setter
    def max_added_time_s(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def max_correlation(self) -> float:
        ...
    @max_correlation.setter
    def max_correlation(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def noise_um(self) -> float:
        """
        0: the session's residual noise
        """
    @noise_um.setter
    def noise_um(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def pose_time_s(self) -> float:
        """
        0: the session's
        """
    @pose_time_s.setter
    def pose_time_s(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def reference_radius_mm(self) -> float:
        ...
    @reference_radius_mm.setter
    def reference_radius_mm(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def rot_step_deg(self) -> float:
        ...
    @rot_step_deg.setter
    def rot_step_deg(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def tilt_step_deg(self) -> float:
        ...
    @tilt_step_deg.setter
    def tilt_step_deg(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
class ProbeSession:
    """
    A rotacal-probe/1 touch-probe session (mm, deg, s).
    """
    def __len__(self) -> int:
        ...
    def __repr__(self) -> str:
        ...
    @property
    def angles_deg(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        tilt and rotary angle of every touch (N, 2), deg
        """
    @property
    def machine(self) -> MachineType:
        ...
    @property
    def n(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        unit approach directions (N, 3), machine frame
        """
    @property
    def noise_um(self) -> float | None:
        ...
    @property
    def pose_names(self) -> list[str]:
        """
        distinct pose labels, in order
        """
    @property
    def poses(self) -> list[str]:
        """
        pose label of every touch
        """
    @property
    def sphere(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        nominal sphere centre, table frame, mm
        """
    @property
    def sphere_diameter(self) -> float:
        ...
    @property
    def stylus_diameter(self) -> float:
        ...
    @property
    def time(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def trigger_radius(self) -> float:
        ...
    @property
    def warnings(self) -> list[str]:
        """
        what the reader found suspicious but kept
        """
    @property
    def xyz(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        latched X, Y, Z (N, 3), mm
        """
class ProbeSphereTrial:
    """
    One place of the sphere the design tried.
    """
    @property
    def plannable(self) -> bool:
        ...
    @property
    def sphere(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def why_not(self) -> str:
        ...
    @property
    def worst_expanded_um(self) -> float:
        ...
class RadialSide:
    """
    Flynn's +-L0 of the radial C test.
    
    Members:
    
      outside
    
      inside
    """
    __members__: typing.ClassVar[dict[str, RadialSide]]  # value = {'outside': <RadialSide.outside: 0>, 'inside': <RadialSide.inside: 1>}
    inside: typing.ClassVar[RadialSide]  # value = <RadialSide.inside: 1>
    outside: typing.ClassVar[RadialSide]  # value = <RadialSide.outside: 0>
    @typing.overload
    def __eq__(self, other: RadialSide) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: RadialSide) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class RealtimeModel:
    """
    A fitted model as a controller's real-time path holds it (realtime/model.hpp).
    """
    def blob(self) -> bytes:
        """
        The blob a controller loads (realtime/blob.hpp).
        """
    def forward(self, joints: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], tool_length: typing.SupportsFloat | typing.SupportsIndex = 0.0, y1: typing.SupportsFloat | typing.SupportsIndex = 0.0, y2: typing.SupportsFloat | typing.SupportsIndex = 0.0, t: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]]:
        """
        (tip (N, 3) mm, direction (N, 3)) relative to the workpiece for joints (N, 5): x, y, z (mm), tilt, rot (rad); y1, y2 the thermal lag states, t the time (s) of the thermal_drift / thermal_warmup terms.
        """
    def inverse(self, world: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], tool_length: typing.SupportsFloat | typing.SupportsIndex = 0.0, y1: typing.SupportsFloat | typing.SupportsIndex = 0.0, y2: typing.SupportsFloat | typing.SupportsIndex = 0.0, t: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 5]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 2]"]]:
        """
        (joints (N, 5), residual (N, 2): tip mm, direction rad) for world (N, 5): the tool tip relative to the workpiece (mm) and the nominal rotary angles (rad).
        """
    @property
    def fingerprint(self) -> int:
        ...
    @property
    def num_effects(self) -> int:
        ...
class RecordSummary:
    def describe(self) -> str:
        ...
    @property
    def crc_errors(self) -> int:
        ...
    @property
    def detail(self) -> str:
        ...
    @property
    def frames(self) -> int:
        ...
    @property
    def garbage_bytes(self) -> int:
        ...
    @property
    def lost(self) -> int:
        ...
    @property
    def malformed(self) -> int:
        ...
    @property
    def outside_window(self) -> int:
        ...
    @property
    def over_range(self) -> int:
        ...
    @property
    def reason(self) -> str:
        ...
    @property
    def rows(self) -> int:
        ...
    @property
    def timeouts(self) -> int:
        ...
class RtestBasis:
    """
    Smooth basis of the position-dependent errors (rtest/identify_joint.hpp).
    """
    def __init__(self, b_degree: typing.SupportsInt | typing.SupportsIndex = 6, c_harmonics: typing.SupportsInt | typing.SupportsIndex = 2, c_b_degree: typing.SupportsInt | typing.SupportsIndex = 1, gamma_cb: bool = False) -> None:
        ...
    def coefficient_names(self, machine: rotacal._core.MachineType | None = None) -> list[str]:
        """
        Names of the map coefficients, tilt-axis map first, in parameter order, with the machine's map names (rtest_map_names; BC-trt's 'BY', 'CB' when no machine is given).
        """
    def for_machine(self, machine: MachineType) -> RtestBasis:
        """
        This basis with the rotations of head axes' maps left out (the sphere is one point).
        """
    @property
    def b_degree(self) -> int:
        """
        highest power of b = B / 90 deg in the B map
        """
    @property
    def b_rotations(self) -> bool:
        """
        rotations in the tilt map (false for a head axis: for_machine)
        """
    @property
    def c_b_degree(self) -> int:
        """
        degree in b of the C-map coefficients
        """
    @property
    def c_harmonics(self) -> int:
        """
        harmonics 1..K of C in the C map
        """
    @property
    def c_rotations(self) -> bool:
        """
        rotations in the rotary map (false for a head axis: for_machine)
        """
    @property
    def gamma_cb(self) -> bool:
        """
        gamma_CB (angular positioning of C) in the C map
        """
class RtestDesign:
    """
    The chosen R-test pattern and the default one.
    """
    @property
    def baseline(self) -> RtestDesignCandidate:
        ...
    @property
    def best(self) -> RtestDesignCandidate:
        ...
    @property
    def candidates(self) -> list[RtestDesignCandidate]:
        ...
    @property
    def ratio(self) -> float:
        ...
    @property
    def time_budget_s(self) -> float:
        ...
class RtestDesignCandidate:
    """
    One R-test pattern, evaluated.
    """
    @property
    def duration_s(self) -> float:
        ...
    @property
    def feasible(self) -> bool:
        ...
    @property
    def names(self) -> list[str]:
        ...
    @property
    def pattern(self) -> RtestPattern:
        ...
    @property
    def sigma(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        predicted 1 sigma at the time budget (mm, rad)
        """
    @property
    def why_not(self) -> str:
        ...
    @property
    def worst_error(self) -> str:
        ...
    @property
    def worst_expanded_um(self) -> float:
        ...
class RtestDesignOptions:
    """
    Options of design_rtest_test (defaults).
    """
    basis: RtestBasis
    def __init__(self) -> None:
        ...
    @property
    def b_limits_deg(self) -> typing.Annotated[list[float], "FixedSize(2)"]:
        ...
    @b_limits_deg.setter
    def b_limits_deg(self, arg0: typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(2)"]) -> None:
        ...
    @property
    def b_step_deg(self) -> list[float]:
        ...
    @b_step_deg.setter
    def b_step_deg(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def base(self) -> RtestPattern:
        """
        the default pattern: nests, grid, dwell
        """
    @base.setter
    def base(self, arg0: RtestPattern) -> None:
        ...
    @property
    def c_step_deg(self) -> list[float]:
        ...
    @c_step_deg.setter
    def c_step_deg(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def nest_height_mm(self) -> list[float]:
        ...
    @nest_height_mm.setter
    def nest_height_mm(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def nest_radius_mm(self) -> list[float]:
        ...
    @nest_radius_mm.setter
    def nest_radius_mm(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def noise_rho(self) -> float:
        ...
    @noise_rho.setter
    def noise_rho(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def noise_um(self) -> float:
        ...
    @noise_um.setter
    def noise_um(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def reference_radius_mm(self) -> float:
        ...
    @reference_radius_mm.setter
    def reference_radius_mm(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def time_budget_s(self) -> float:
        """
        0: the base pattern's run time
        """
    @time_budget_s.setter
    def time_budget_s(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def travel_max(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @travel_max.setter
    def travel_max(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def travel_min(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        """
        X, Y, Z, mm (formats.md frame)
        """
    @travel_min.setter
    def travel_min(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
class RtestJointIdentification(Identification):
    @property
    def model(self) -> RtestJointModel:
        ...
    @property
    def probe_zeros(self) -> dict[str, typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]]:
        ...
    @property
    def residuals(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        """
        measured - model per sample (N, 3) = (dx, dy, dz), mm.
        """
class RtestJointModel:
    """
    Location errors, tool_offset_Z (machines with head axes) and smooth error maps of the tilt and the rotary axis of any machine, with covariance.
    """
    def __init__(self, machine: MachineType, basis: RtestBasis, params: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], covariance: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], observable: collections.abc.Sequence[bool]) -> None:
        """
        Rebuild a model from its parts (checked against the basis: rtest/predict.hpp).
        """
    def parameter_names(self) -> list[str]:
        """
        Names of params in order: location errors, 'tool_offset_Z' on a machine with head axes, then the map coefficients.
        """
    def readings(self, q: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], angles: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]]:
        """
        R-test readings (N, 3) of the nest at q (table frame, mm) at angles (N, 2) = (B, C) in rad, without probe zero, and their 1-sigma (N, 3) (NaN where an unobservable parameter enters).
        """
    def table_errors(self, q: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], angles: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]]:
        """
        Error T q - T_nominal q (N, 3) of the table point q (mm) at angles (N, 2) in rad, machine frame, mm, and its 1-sigma.
        """
    def tool_errors(self, xyz: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], angles: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]]:
        """
        Error of the sphere (N, 3), actual - nominal, machine frame, mm, for commanded xyz (N, 3) at angles (N, 2) = (tilt, rotary) in rad, and its 1-sigma; zero without head axes.
        """
    def w_by(self, B: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"]) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 6]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 6]"]]:
        """
        B-axis map (N, 6) = (dx, dy, dz, alpha, beta, gamma)_BY (mm, rad) at B (N,) in rad, and its 1-sigma.
        """
    def w_cb(self, angles: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 6]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 6]"]]:
        """
        C-axis map (N, 6) at angles (N, 2) = (B, C) in rad, and its 1-sigma.
        """
    @property
    def basis(self) -> RtestBasis:
        ...
    @property
    def covariance(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
    @property
    def machine(self) -> MachineType:
        ...
    @property
    def observable(self) -> list[bool]:
        ...
    @property
    def params(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        """
        8 location errors, tool_offset_Z (machines with head axes), then the map coefficients (mm, rad): parameter_names() order
        """
class RtestMonteCarlo:
    @property
    def draws(self) -> int:
        ...
    @property
    def noise(self) -> str:
        ...
    @property
    def parameters(self) -> list[MonteCarloParameter]:
        ...
    @property
    def values(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, n]"]:
        ...
class RtestPaperIdentification:
    @property
    def b_deg(self) -> list[float]:
        ...
    @property
    def c_deg(self) -> list[float]:
        ...
    @property
    def method(self) -> str:
        ...
    @property
    def n_samples(self) -> int:
        ...
    @property
    def notes(self) -> list[str]:
        ...
    @property
    def residual_rms_um(self) -> float:
        ...
    @property
    def unobservable(self) -> list[str]:
        ...
class RtestPattern:
    """
    The pose grid and nests of a simulated session.
    """
    def __init__(self) -> None:
        ...
    @property
    def b_deg(self) -> list[float]:
        """
        B positions, deg (outer loop)
        """
    @b_deg.setter
    def b_deg(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def c_deg(self) -> list[float]:
        """
        C positions, deg (inner loop)
        """
    @c_deg.setter
    def c_deg(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def dwell_s(self) -> float:
        """
        time between poses, s
        """
    @dwell_s.setter
    def dwell_s(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def nests(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]:
        """
        (K, 3) nominal ball centres, table frame, mm
        """
    @nests.setter
    def nests(self, arg1: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> None:
        ...
class RtestSeparatingCandidate:
    """
    An added nest, evaluated with the session.
    """
    @property
    def added(self) -> RtestPattern:
        ...
    @property
    def correlation(self) -> float:
        ...
    @property
    def description(self) -> str:
        ...
    @property
    def determined(self) -> bool:
        ...
    @property
    def duration_s(self) -> float:
        ...
    @property
    def repeats(self) -> float:
        ...
class RtestSeparationDesign:
    """
    The added nest that separates two effects, or why none can.
    """
    @property
    def already_separated(self) -> bool:
        ...
    @property
    def candidates_tried(self) -> int:
        ...
    @property
    def chosen(self) -> RtestSeparatingCandidate:
        ...
    @property
    def correlation_before(self) -> float:
        ...
    @property
    def effective_per_reading(self) -> float:
        ...
    @property
    def effects(self) -> typing.Annotated[list[str], "FixedSize(2)"]:
        ...
    @property
    def found(self) -> bool:
        ...
    @property
    def motion(self) -> TableMotionOverlap:
        ...
    @property
    def names(self) -> list[str]:
        ...
    @property
    def noise_um(self) -> float:
        ...
    @property
    def sigma_after(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def sigma_before(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def verdict(self) -> str:
        ...
class RtestSeparationOptions:
    """
    Options of design_rtest_separation (defaults).
    """
    def __init__(self) -> None:
        ...
    @property
    def b_limits_deg(self) -> typing.Annotated[list[float], "FixedSize(2)"]:
        ...
    @b_limits_deg.setter
    def b_limits_deg(self, arg0: typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(2)"]) -> None:
        ...
    @property
    def b_step_deg(self) -> list[float]:
        ...
    @b_step_deg.setter
    def b_step_deg(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def c_step_deg(self) -> list[float]:
        ...
    @c_step_deg.setter
    def c_step_deg(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def dwell_s(self) -> float:
        """
        0: the session's
        """
    @dwell_s.setter
    def dwell_s(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def max_added_time_s(self) -> float:
        ...
    @max_added_time_s.setter
    def max_added_time_s(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def max_correlation(self) -> float:
        ...
    @max_correlation.setter
    def max_correlation(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def nest_angle_deg(self) -> list[float]:
        ...
    @nest_angle_deg.setter
    def nest_angle_deg(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def nest_height_mm(self) -> list[float]:
        ...
    @nest_height_mm.setter
    def nest_height_mm(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def nest_radius_mm(self) -> list[float]:
        ...
    @nest_radius_mm.setter
    def nest_radius_mm(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def noise_um(self) -> float:
        """
        0: the session's residual noise
        """
    @noise_um.setter
    def noise_um(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def reference_radius_mm(self) -> float:
        ...
    @reference_radius_mm.setter
    def reference_radius_mm(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def travel_max(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @travel_max.setter
    def travel_max(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def travel_min(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @travel_min.setter
    def travel_min(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
class RtestSession:
    """
    A rotacal-rtest/1 session (mm, deg, s).
    """
    def __len__(self) -> int:
        ...
    def __repr__(self) -> str:
        ...
    def with_displacements(self, d: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 3]"]) -> RtestSession:
        ...
    @property
    def angles_deg(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 2]"]:
        ...
    @property
    def d(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]:
        """
        dx, dy, dz (N,3), table frame, mm
        """
    @property
    def machine(self) -> MachineType:
        ...
    @property
    def metadata(self) -> dict:
        ...
    @property
    def nests(self) -> dict[str, typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]]:
        ...
    @property
    def noise_um(self) -> float | None:
        ...
    @property
    def probe_dirs(self) -> dict[int, typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]]:
        ...
    @property
    def setups(self) -> list[str]:
        """
        set-up (nest) label of every pose
        """
    @property
    def time(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def warnings(self) -> list[str]:
        """
        what the reader found suspicious but kept
        """
    @property
    def xyz(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]:
        ...
class RtestSimOptions:
    """
    Options of simulate_rtest (defaults).
    """
    pattern: RtestPattern
    write_d: bool
    def __init__(self) -> None:
        ...
    @property
    def noise_um(self) -> float:
        """
        1-sigma reading noise, um
        """
    @noise_um.setter
    def noise_um(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def probe_zero_um(self) -> float:
        """
        1-sigma of each component of the per-set-up probe zero, um
        """
    @probe_zero_um.setter
    def probe_zero_um(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def seed(self) -> int:
        ...
    @seed.setter
    def seed(self, arg0: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
class SegmentKind:
    """
    Members:
    
      test
    
      rotary_transition
    
      arc_transition
    """
    __members__: typing.ClassVar[dict[str, SegmentKind]]  # value = {'test': <SegmentKind.test: 0>, 'rotary_transition': <SegmentKind.rotary_transition: 1>, 'arc_transition': <SegmentKind.arc_transition: 2>}
    arc_transition: typing.ClassVar[SegmentKind]  # value = <SegmentKind.arc_transition: 2>
    rotary_transition: typing.ClassVar[SegmentKind]  # value = <SegmentKind.rotary_transition: 1>
    test: typing.ClassVar[SegmentKind]  # value = <SegmentKind.test: 0>
    @typing.overload
    def __eq__(self, other: SegmentKind) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: SegmentKind) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class SeparatingCandidate:
    """
    An added test, evaluated with the session.
    """
    @property
    def correlation(self) -> float:
        ...
    @property
    def description(self) -> str:
        ...
    @property
    def determined(self) -> bool:
        ...
    @property
    def duration_s(self) -> float:
        ...
    @property
    def new_pivot(self) -> bool:
        ...
    @property
    def setup(self) -> BallbarSetup:
        ...
    @property
    def slow_down(self) -> float:
        ...
class SeparationDesign:
    """
    The added test that separates two effects, or why none can.
    """
    @property
    def already_separated(self) -> bool:
        ...
    @property
    def candidates_tried(self) -> int:
        ...
    @property
    def chosen(self) -> SeparatingCandidate:
        ...
    @property
    def correlation_before(self) -> float:
        ...
    @property
    def effective_per_reading(self) -> float:
        ...
    @property
    def effects(self) -> typing.Annotated[list[str], "FixedSize(2)"]:
        ...
    @property
    def found(self) -> bool:
        ...
    @property
    def motion(self) -> TableMotionOverlap:
        ...
    @property
    def names(self) -> list[str]:
        ...
    @property
    def noise_um(self) -> float:
        ...
    @property
    def sigma_after(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def sigma_before(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
        ...
    @property
    def verdict(self) -> str:
        ...
class SeparationOptions:
    """
    Options of design_ballbar_separation (defaults).
    """
    def __init__(self) -> None:
        ...
    @property
    def added(self) -> BallbarSetup:
        """
        step, feeds and C range of the added test
        """
    @added.setter
    def added(self, arg0: BallbarSetup) -> None:
        ...
    @property
    def bar_lengths_mm(self) -> list[float]:
        ...
    @bar_lengths_mm.setter
    def bar_lengths_mm(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def max_added_time_s(self) -> float:
        ...
    @max_added_time_s.setter
    def max_added_time_s(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def max_correlation(self) -> float:
        ...
    @max_correlation.setter
    def max_correlation(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def noise_um(self) -> float:
        """
        0: the session's residual noise
        """
    @noise_um.setter
    def noise_um(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def pivot_angle_deg(self) -> list[float]:
        ...
    @pivot_angle_deg.setter
    def pivot_angle_deg(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def pivot_radius_mm(self) -> list[float]:
        ...
    @pivot_radius_mm.setter
    def pivot_radius_mm(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def pivot_z_mm(self) -> list[float]:
        ...
    @pivot_z_mm.setter
    def pivot_z_mm(self, arg0: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex]) -> None:
        ...
    @property
    def reference_radius_mm(self) -> float:
        ...
    @reference_radius_mm.setter
    def reference_radius_mm(self, arg0: typing.SupportsFloat | typing.SupportsIndex) -> None:
        ...
    @property
    def tilt_limits_deg(self) -> typing.Annotated[list[float], "FixedSize(2)"]:
        ...
    @tilt_limits_deg.setter
    def tilt_limits_deg(self, arg0: typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(2)"]) -> None:
        ...
    @property
    def travel_max(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @travel_max.setter
    def travel_max(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
    @property
    def travel_min(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @travel_min.setter
    def travel_min(self, arg0: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]) -> None:
        ...
class SerialError(IoError):
    pass
class SphereFit:
    @property
    def centre(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def converged(self) -> bool:
        ...
    @property
    def covariance(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[4, 4]"]:
        """
        (cx, cy, cz, r), 1-sigma^2
        """
    @property
    def n(self) -> int:
        ...
    @property
    def radius(self) -> float:
        ...
    @property
    def rms(self) -> float:
        ...
class SphereOffsetCalibration:
    """
    Sphere offset from the spindle axis.
    """
    @property
    def centre(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def offset(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 1]"]:
        """
        (x, y) at spindle angle 0, mm
        """
    @property
    def offset_std(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[2, 1]"]:
        ...
    @property
    def residual_rms_um(self) -> float:
        ...
class SweepDirection:
    """
    ccw: towards increasing angles; cw: back.
    
    Members:
    
      ccw
    
      cw
    """
    __members__: typing.ClassVar[dict[str, SweepDirection]]  # value = {'ccw': <SweepDirection.ccw: 0>, 'cw': <SweepDirection.cw: 1>}
    ccw: typing.ClassVar[SweepDirection]  # value = <SweepDirection.ccw: 0>
    cw: typing.ClassVar[SweepDirection]  # value = <SweepDirection.cw: 1>
    @typing.overload
    def __eq__(self, other: SweepDirection) -> bool:
        ...
    @typing.overload
    def __eq__(self, other: typing.Any) -> bool:
        ...
    def __getstate__(self) -> int:
        ...
    def __hash__(self) -> int:
        ...
    def __index__(self) -> int:
        ...
    def __init__(self, value: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __int__(self) -> int:
        ...
    @typing.overload
    def __ne__(self, other: SweepDirection) -> bool:
        ...
    @typing.overload
    def __ne__(self, other: typing.Any) -> bool:
        ...
    def __repr__(self) -> str:
        ...
    def __setstate__(self, state: typing.SupportsInt | typing.SupportsIndex) -> None:
        ...
    def __str__(self) -> str:
        ...
    @property
    def name(self) -> str:
        ...
    @property
    def value(self) -> int:
        ...
class TableMotionOverlap:
    """
    Whether two effects move the table alike (ballbar/design.hpp).
    """
    @property
    def cosine(self) -> float:
        """
        largest cosine of the principal angles
        """
    @property
    def first_is_location(self) -> bool:
        ...
    @property
    def moves_table_first(self) -> bool:
        ...
    @property
    def moves_table_second(self) -> bool:
        ...
    @property
    def same_motion(self) -> bool:
        """
        no instrument can separate them
        """
    @property
    def second_is_location(self) -> bool:
        ...
    @property
    def why(self) -> str:
        ...
class TransitionArc:
    """
    Great-circle arc about the pivot at rotary zero (mm, rad).
    """
    @property
    def angle(self) -> float:
        ...
    @property
    def axis(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def center(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def end(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
    @property
    def principal_axis(self) -> int:
        ...
    @property
    def start(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]:
        ...
class UncertaintyBudget:
    @property
    def coverage(self) -> float:
        ...
    @property
    def errors(self) -> list[LocationBudget]:
        ...
class Unexplained:
    @property
    def at(self) -> float:
        ...
    @property
    def axis(self) -> str:
        ...
    @property
    def chi2_per_dof(self) -> float:
        ...
    @property
    def group(self) -> str:
        ...
    @property
    def noise_structure(self) -> str:
        ...
    @property
    def noise_structure_p(self) -> float:
        ...
    @property
    def noise_um(self) -> float:
        ...
    @property
    def p_value(self) -> float:
        ...
    @property
    def present(self) -> bool:
        ...
    @property
    def range_from(self) -> float:
        ...
    @property
    def range_to(self) -> float:
        ...
    @property
    def signature(self) -> str:
        ...
    @property
    def size_um(self) -> float:
        ...
    @property
    def suggested_test(self) -> str:
        ...
class UnobservableEffect:
    @property
    def effect(self) -> str:
        ...
    @property
    def reason(self) -> str:
        ...
class VirtualBallbar:
    """
    A ballbar on a simulated machine, served on a pseudo-terminal.
    """
    def __init__(self, plan: BallbarPlan, truth: BallbarMachineModel, noise_um: typing.SupportsFloat | typing.SupportsIndex = 0.5, seed: typing.SupportsInt | typing.SupportsIndex = 1, rate_hz: typing.SupportsFloat | typing.SupportsIndex = 1000.0, speed: typing.SupportsFloat | typing.SupportsIndex = 1.0, baud: typing.SupportsInt | typing.SupportsIndex = 115200, faults: FaultInjection = ...) -> None:
        ...
    def start(self) -> None:
        ...
    def stats(self) -> dict:
        ...
    def stop(self) -> None:
        ...
    @property
    def finished(self) -> bool:
        ...
    @property
    def port(self) -> str:
        ...
class VirtualCircularBallbar:
    """
    A ballbar on a machine running an ISO 230-4 circular program (circular/timeline.hpp), served on a pseudo-terminal; the machine and noise as simulate_circular's options.
    """
    def __init__(self, plan: CircularPlanResult, options: CircularSimulationOptions, rate_hz: typing.SupportsFloat | typing.SupportsIndex = 250.0, speed: typing.SupportsFloat | typing.SupportsIndex = 1.0, baud: typing.SupportsInt | typing.SupportsIndex = 115200, faults: FaultInjection = ...) -> None:
        ...
    def start(self) -> None:
        ...
    def stats(self) -> dict:
        ...
    def stop(self) -> None:
        ...
    @property
    def finished(self) -> bool:
        ...
    @property
    def port(self) -> str:
        ...
class VirtualRtest:
    """
    An R-test on a simulated B/C table, served on a pseudo-terminal.
    """
    def __init__(self, machine: MachineType, errors: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], effects: collections.abc.Sequence[str], effect_params: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], b_deg: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], c_deg: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], nests: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], dwell_s: typing.SupportsFloat | typing.SupportsIndex, noise_um: typing.SupportsFloat | typing.SupportsIndex, probe_zero_um: typing.SupportsFloat | typing.SupportsIndex, probe_dirs: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], seed: typing.SupportsInt | typing.SupportsIndex, mode: str = 'keyence', rate_hz: typing.SupportsFloat | typing.SupportsIndex = 100.0, speed: typing.SupportsFloat | typing.SupportsIndex = 1.0, baud: typing.SupportsInt | typing.SupportsIndex = 115200, faults: FaultInjection = ...) -> None:
        ...
    def start(self) -> None:
        ...
    def stats(self) -> dict:
        ...
    def stop(self) -> None:
        ...
    @property
    def finished(self) -> bool:
        ...
    @property
    def port(self) -> str:
        ...
    @property
    def probe_zeros(self) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]:
        ...
    @property
    def program(self) -> RtestSession:
        """
        Commanded rows (set-up, time, B, C, X, Y, Z) and nests.
        """
def analyze_circular(session: BallbarSession) -> CircularAnalysis:
    """
    ISO 230-4 circular deviation G per run, G(b) and hysteresis H per cw/ccw pair.
    """
def angle_maps(model_path: str, lo_deg: typing.SupportsFloat | typing.SupportsIndex, hi_deg: typing.SupportsFloat | typing.SupportsIndex, spacing_deg: typing.SupportsFloat | typing.SupportsIndex, samples_between: typing.SupportsInt | typing.SupportsIndex = 16) -> list[AxisAngleMap]:
    """
    The position-dependent errors of a model file's table axes as functions of each axis' angle (io/angle_map.hpp), sampled from lo_deg to hi_deg.
    """
def ballbar_model_document(model: ...) -> typing.Any:
    ...
def ballbar_model_from_document(document: dict, source: str = '<model>') -> ...:
    ...
def box_least_squares(R: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, n]"], d: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], w: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], bounds: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], max_sweeps: typing.SupportsInt | typing.SupportsIndex = 200, tolerance: typing.SupportsFloat | typing.SupportsIndex = 1e-09) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    """
    min sum w (d - R s)^2 with abs(s_j) <= bounds_j, by cyclic coordinate descent.
    
    Parameters
    ----------
    R : (N, K) array
    d, w : (N,) arrays, w >= 0
    bounds : (K,) array, >= 0
    max_sweeps, tolerance : stop after max_sweeps passes, or when no s_j moves by more than
        tolerance * bounds_j
    
    Returns s (K,). Raises rotacal.InvalidArgument for mismatched sizes or non-finite input.
    """
def budget_diagnosis_ballbar(session: BallbarSession, options: DiagnosisOptions = ...) -> Diagnosis:
    """
    The diagnosis a budget rests on: a long session searched on a reduced design, what it found diagnosed on every reading (diagnose/ballbar_diagnosis.hpp).
    """
def builtin_machine_names() -> list[str]:
    """
    Names of the built-in machines.
    """
def calibrate_probe_directions(moves: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], readings: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> ProbeCalibration:
    """
    Probe directions, gains and zeros from commanded moves (N, 3) and readings (N, 3), mm.
    """
def calibrate_sphere_offset(dirs: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], angles: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], readings: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> SphereOffsetCalibration:
    """
    Sphere offset from spindle indexing: angles (N,) rad, readings (N, 3) mm.
    """
def check_json_bounds(text: str, source: str) -> None:
    """
    Refuse JSON text nested deeper than 64 levels or with more objects and arrays than its size allows (core/json_text.hpp): ParseError naming source, line and column. The syntax is not checked.
    """
def check_model_machine(model_machine: MachineType, session_machine: MachineType, model_source: str) -> None:
    ...
def check_output(path: str, inputs: collections.abc.Sequence[str] = [], other_outputs: collections.abc.Sequence[str] = []) -> str:
    """
    Check an output path without writing: 'replace' or 'write-through'; raises IoError.
    """
@typing.overload
def check_plausible(session: BallbarSession, source: str, options: PlausibilityOptions = ...) -> PlausibilityReport:
    """
    Refuse (InvalidArgument, likely cause named) a session the nominal kinematics cannot explain.
    """
@typing.overload
def check_plausible(session: RtestSession, source: str, options: PlausibilityOptions = ...) -> PlausibilityReport:
    ...
@typing.overload
def check_plausible(session: ..., source: str, options: PlausibilityOptions = ...) -> PlausibilityReport:
    ...
def check_rtest_pattern(machine: MachineType, b_deg: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], c_deg: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], nests: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> None:
    """
    Raise InvalidArgument naming the axis and its limits (or the travel) when a tilt (b_deg) or rotary (c_deg) angle, deg, or a commanded X, Y, Z of a nest (K, 3) is outside the machine's limits.
    """
def circular_catalogue() -> list[CircularEffect]:
    ...
def circular_commanded_session(plan: CircularPlanResult) -> BallbarSession:
    """
    The commanded rotacal-ballbar/1 session of a circular plan (length = L0).
    """
def circular_label(plane: CircularPlane, direction: CircularDirection, feed_mm_per_min: typing.SupportsFloat | typing.SupportsIndex, with_feed: bool) -> str:
    ...
def comment_lines(dialect: str, text: str) -> list[str]:
    """
    text as whole comment lines of a file a controller executes (io/controller_comment.hpp), without line ends; dialect: linuxcnc, fanuc, heidenhain, siemens, isg or hash (HAL, parameter lists). Every free text written into such a file goes through it.
    """
def compensate_commands(nominal: BallbarSession, identified: ..., machine: MachineType, tool_length_error: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> BallbarSession:
    """
    Compensated commands; tool_length_error (mm): the error of pivot_length + tool_length of a head machine (minus the identified tool_offset_Z).
    """
def compensate_sphere_offset(session: RtestSession, offset: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> RtestSession:
    """
    The session with the sphere's offset (x, y) from the spindle axis taken out of every d.
    """
def controller_parameter_names(controller: str, machine: MachineType, toolholder: typing.SupportsInt | typing.SupportsIndex = 1) -> list[str]:
    """
    The names of the current values an export reads, in the order it writes them.
    """
def default_axial_c_tilt_deg(machine: MachineType) -> float:
    ...
def default_ballbar_tests() -> list[BallbarTest]:
    """
    sphere_xy, sphere_yz, sphere_zx, radial tilt, axial C, radial C, axial tilt.
    """
def default_calibration_moves(step_mm: typing.SupportsFloat | typing.SupportsIndex = 0.5) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]:
    """
    +-step along X, Y, Z and the 4 body diagonals (14, 3), mm.
    """
def default_probe_poses_deg(machine: MachineType) -> tuple[typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 2]"], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]]:
    """
    (poses (P, 2) tilt and rotary deg, directions (K, 3)) of default_probe_pattern.
    """
def default_rtest_pattern(machine: MachineType) -> RtestPattern:
    """
    The paper's pattern fitted to a machine: tilt angles inside its limits (-90..90 every 30 deg where they allow), the rotary axis every 30 deg, the two paper nests halved until every commanded X, Y, Z is inside the travel (rtest/simulate.hpp).
    """
def default_tilt_range_deg(machine: MachineType) -> typing.Annotated[list[float], "FixedSize(2)"]:
    ...
def design_ballbar_separation(session: BallbarSession, pair: collections.abc.Sequence[str], options: SeparationOptions = ...) -> SeparationDesign:
    """
    The smallest added test that separates two effects after a session (ballbar/design.hpp).
    """
def design_ballbar_test(options: BallbarDesignOptions) -> BallbarDesign:
    """
    The pivot and bar length with the smallest predicted uncertainty (ballbar/design.hpp).
    """
def design_probe_separation(session: ProbeSession, pair: collections.abc.Sequence[str], options: ProbeSeparationOptions = ...) -> ProbeSeparationDesign:
    """
    The smallest added set of poses that separates two effects after a touch-probe session (probe/design.hpp).
    """
def design_probe_test(options: ProbeDesignOptions) -> ProbeDesign:
    """
    The poses and touches with the smallest predicted uncertainty (probe/design.hpp).
    """
def design_rtest_separation(session: RtestSession, pair: collections.abc.Sequence[str], options: RtestSeparationOptions = ...) -> RtestSeparationDesign:
    """
    The smallest added R-test nest that separates two effects after a session (rtest/design.hpp).
    """
def design_rtest_test(options: RtestDesignOptions) -> RtestDesign:
    """
    The R-test nests and pose grid with the smallest predicted uncertainty (rtest/design.hpp).
    """
def diagnose_ballbar(session: BallbarSession, options: DiagnosisOptions = ..., reference: rotacal._core.BallbarSession | None = None) -> Diagnosis:
    """
    Diagnose a ballbar session: baseline fit, residual structure, catalogue candidates, findings with their gain.
    """
def diagnose_circular(session: BallbarSession, options: CircularDiagnosisOptions = ...) -> CircularDiagnosis:
    """
    The classic causes the circular runs support, each with parameters, 1-sigma and gain.
    """
def diagnose_probe(session: ProbeSession, options: DiagnosisOptions = ...) -> Diagnosis:
    """
    Diagnose a touch-probe session (diagnose/probe_diagnosis.hpp): catalogue effects and the probe's stylus_radius_offset and probe_lobing over the joint fit's baseline.
    """
def diagnose_rtest(session: RtestSession, options: DiagnosisOptions = ...) -> Diagnosis:
    """
    Diagnose an R-test session (baseline: location errors and a probe zero per set-up).
    """
def diagnose_sessions(sessions: collections.abc.Sequence[tuple[str, typing.Any]], options: DiagnosisOptions = ...) -> MultiDiagnosis:
    """
    One diagnosis of several (name, session) pairs of one machine (diagnose/multi_session.hpp): machine effects shared, instrument, set-up and time effects per session (ids 'name:id').
    """
def displacements_from_raw(session: RtestSession, dirs: typing.Annotated[numpy.typing.ArrayLike, numpy.float64] | None = None) -> RtestSession:
    """
    Fill dx,dy,dz from raw d1,d2,d3 with the session's probe.N.dir, or with calibrated dirs (3, 3) (rows keep a dx,dy,dz they already have).
    """
def effect_catalogue(machine: MachineType, max_harmonic: typing.SupportsInt | typing.SupportsIndex = 4) -> list[Effect]:
    """
    Every catalogue entry that applies to the machine, harmonics 1..max_harmonic.
    """
def estimate_noise_model(groups: collections.abc.Sequence[str], times: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], residuals_mm: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], options: NoiseModelOptions = ...) -> NoiseModel:
    """
    AR(p) model (Burg, BIC order) of the residuals per stream (group, channel).
    """
def evaluate_rtest_design(pattern: RtestPattern, options: RtestDesignOptions, time_budget_s: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> RtestDesignCandidate:
    """
    One R-test pattern evaluated at a time budget (0: its own run time).
    """
def export_controller(model_path: str, controller: str, current_text: str | None = None, current_source: str = '<current>', toolholder: typing.SupportsInt | typing.SupportsIndex = 1, generated_at: str = '', thermal_at_s: typing.SupportsFloat | typing.SupportsIndex | None = None, thermal_state: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex] | None = None) -> ControllerExport:
    """
    Export a model file's location errors into a controller's kinematic parameters (io/controller_export.hpp); current_text: the controller's current values (its HAL/MPF file or the documented JSON), None for zero offsets. A thermal model at thermal_at_s (s of the test's duty from its first row) or at thermal_state (y per lag): its errors there.
    """
def fanuc_pitch_tables(model_path: str, spacing_deg: typing.SupportsFloat | typing.SupportsIndex = 5.0, range_deg: collections.abc.Mapping[str, typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(2)"]] = {}, fanuc: FanucPitchOptions = ..., generated_at: str = '') -> CompensationTables:
    """
    FANUC pitch error compensation data (parameters 3620-3625 and values by data number) of each table axis' positioning error (io/compensation_table.hpp).
    """
def format_ballbar(session: BallbarSession) -> str:
    ...
def format_model_document(document: dict, source: str = 'model') -> str:
    """
    Strict JSON text of a model document (non-finite numbers as null with a reason), validated.
    """
def format_probe(session: ProbeSession) -> str:
    ...
def format_rtest(session: RtestSession) -> str:
    ...
def forward(machine: MachineType, errors: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], angles: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], q_table: typing.Annotated[numpy.typing.ArrayLike, numpy.float64]) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]:
    """
    Machine-frame positions of table points.
    
    Parameters
    ----------
    machine : MachineType
    errors : (8,) location errors, order of location_error_names (mm, rad)
    angles : (N, 2) tilt and C angles, rad
    q_table : (N, 3) points in the table frame, mm
    
    Returns
    -------
    (N, 3) machine-frame positions, mm
    """
def hyper_circle_fit(points: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], sigma: typing.SupportsFloat | typing.SupportsIndex = 0.0, refine: bool = False) -> CircleFit:
    """
    Circle fit to (N, 2) points.
    
    Parameters
    ----------
    points : (N, 2) array
    sigma : known 1-sigma noise of the points (0: estimated from the residuals)
    refine : polish by orthogonal distances (Ceres)
    
    Raises rotacal.DegenerateGeometry for < 3, collinear points or a too short arc.
    """
def identify_joint(session: BallbarSession, fit_length_offset: bool = False, effects: collections.abc.Sequence[str] = [], tests: collections.abc.Sequence[str] = [], noise: str = 'auto') -> BallbarIdentification:
    """
    Joint fit (noise 'auto': AR noise model of the residuals, GLS refit when correlated; 'white') of the 8 location errors and the actual pivot to every sample (core/joint_fit.hpp).
    """
def identify_multi(sessions: collections.abc.Sequence[tuple[str, typing.Any]], noise: str = 'auto', effects: collections.abc.Sequence[str] = [], inflate_sigma: bool = False, same_setup: collections.abc.Mapping[str, str] = {}) -> MultiIdentification:
    """
    One identification from several (name, session) pairs of one machine (multi/identify.hpp): one set of location errors (and of the catalogue effects `effects`), each session's own nuisances and noise model, and the disagreements between the sessions fitted alone; noise 'auto' or 'white'; inflate_sigma: widen the sigmas of disagreeing parameters by their Birge ratio; same_setup: session name -> the earlier session whose set-up it continues, sharing its own parameters (pivot, nest zeros).
    """
def identify_paper(session: BallbarSession) -> BallbarIdentification:
    """
    Flynn et al. 2016's chain: sphere fit, Hyper circle fits, SVD plane fits, transport.
    """
def identify_probe(session: ProbeSession, effects: collections.abc.Sequence[str] = [], noise: str = 'auto') -> ProbeIdentification:
    """
    Joint fit of every touch: location errors, the sphere's table position (and effects), with observability and the noise model (probe/identify.hpp); noise 'auto' or 'white'.
    """
def identify_probe_cycles(session: ProbeSession, radius_known: bool = True) -> ProbeIdentification:
    """
    The controller cycles' method: sphere per pose, plane and circle of the centres per table axis.
    """
def identify_rtest_joint(session: RtestSession, basis: RtestBasis = ..., noise: str = 'auto') -> RtestJointIdentification:
    """
    Joint fit of an R-test session: location errors, smooth B and C maps, a probe zero per set-up, with observability (rtest/identify_joint.hpp); noise 'auto' (AR noise model, GLS refit when correlated) or 'white'.
    """
def identify_rtest_paper(session: RtestSession) -> RtestPaperIdentification:
    """
    Oyama & Ibaraki's method, Eqs. 10-22 (rtest/identify_paper.hpp).
    """
def identify_runs(setup: BallbarSetup, machines: collections.abc.Sequence[BallbarMachineModel], compensate_for: typing.Annotated[numpy.typing.ArrayLike, numpy.float64] | None = None, seeds: collections.abc.Sequence[typing.SupportsInt | typing.SupportsIndex] = [], method: str = 'paper', noise_um: typing.SupportsFloat | typing.SupportsIndex = 0.5, noise_rho: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 8]"]:
    """
    Location errors identified from one run on each machine (Flynn et al. 2016, Sec. 4).
    
    Parameters
    ----------
    setup : BallbarSetup of the planned test
    machines : [BallbarMachineModel], one run each
    compensate_for : (N, 8) location errors the test of run i is compensated for (None: nominal)
    seeds : one AR(1) noise seed per run ([]: noise-free)
    method : identification, "paper" or "joint"
    noise_um, noise_rho : reading noise, um, and its AR(1) correlation
    
    Returns
    -------
    (N, 8) identified location errors, mm and rad, in location_error_names order
    """
def identify_thermal(path: str, lags: typing.SupportsInt | typing.SupportsIndex = 1, tolerance_mm: typing.SupportsFloat | typing.SupportsIndex | None = None, tolerance_rad: typing.SupportsFloat | typing.SupportsIndex | None = None, noise: str = 'auto', peer: bool = False, model: bool = False) -> typing.Any:
    """
    Identify a thermal probe or R-test session (one joint fit over every row).
    
    Parameters
    ----------
    path : str
        A ``rotacal-probe/1`` or ``rotacal-rtest/1`` file with an ``epoch`` column and
        ``# duty.N:`` lines.
    lags : int
        1, or 2 (a fast and a slow lag).
    tolerance_mm, tolerance_rad : float, optional
        The drift the user tolerates, for the time from cold after which it may exceed it.
    noise : str
        "auto": AR noise model of the residuals, GLS refit when correlated; "white".
    peer : bool
        Also the per-epoch peer (touch probe): each epoch identified alone, then one lag fitted
        to the series; under ``peer``, as the joint fit's.
    model : bool
        Also the thermal model file's document (``model``; io/thermal_model.hpp), without its
        ``source``.
    
    Returns
    -------
    dict
        ``identification`` (cold values, each lag's tau and gains with sigma or the reason they
        are unobservable), ``summary`` (steady-state change at the tested speed, significance,
        time to exceed the tolerance, tau), ``warnings``.
    """
def is_machine_effect(effect: Effect) -> bool:
    """
    True for an effect of the machine (one parameter set shared by every session).
    """
def is_rotary_test(test: BallbarTest) -> bool:
    ...
def is_thermal_session(path: str) -> bool:
    """
    True when the file has an ``epoch`` column or ``# duty.N:`` lines.
    """
def isg_tables(model_path: str, spacing_deg: typing.SupportsFloat | typing.SupportsIndex = 5.0, range_deg: collections.abc.Mapping[str, typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(2)"]] = {}, axis_numbers: collections.abc.Mapping[str, typing.SupportsInt | typing.SupportsIndex] = {}, max_points: typing.SupportsInt | typing.SupportsIndex = 0, max_cross_points: typing.SupportsInt | typing.SupportsIndex = 0, generated_at: str = '') -> CompensationTables:
    """
    ISG compensation value lists: kw.ssfk of each table axis' positioning error, kw.crosscomp of its translations (io/compensation_table.hpp); max_points 0: kw_nr_max 1500; max_cross_points 0: 1000.
    """
def kasa_circle_fit(points: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], sigma: typing.SupportsFloat | typing.SupportsIndex = 0.0, refine: bool = False) -> CircleFit:
    """
    Circle fit to (N, 2) points.
    
    Parameters
    ----------
    points : (N, 2) array
    sigma : known 1-sigma noise of the points (0: estimated from the residuals)
    refine : polish by orthogonal distances (Ceres)
    
    Raises rotacal.DegenerateGeometry for < 3, collinear points or a too short arc.
    """
def linuxcnc_comp_tables(model_path: str, spacing_deg: typing.SupportsFloat | typing.SupportsIndex = 5.0, range_deg: collections.abc.Mapping[str, typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(2)"]] = {}, file_names: collections.abc.Mapping[str, str] = {}, max_points: typing.SupportsInt | typing.SupportsIndex = 0, generated_at: str = '') -> CompensationTables:
    """
    LinuxCNC COMP_FILEs (type 1) of each table axis' positioning error and the INI lines that load them (io/compensation_table.hpp); max_points 0: LinuxCNC's 256.
    """
def list_serial_ports() -> list[tuple[str, str, str]]:
    """
    (path, description, transport) of every serial port libserialport finds.
    """
def location_error_names(machine: MachineType) -> typing.Annotated[list[str], "FixedSize(8)"]:
    """
    ISO 230-7 names of the 8 location errors, in the order of every errors vector.
    """
def machine_name(machine: MachineType) -> str:
    ...
def monte_carlo_joint(session: BallbarSession, result: BallbarIdentification, draws: typing.SupportsInt | typing.SupportsIndex = 100, seed: typing.SupportsInt | typing.SupportsIndex = 1, noise_um: typing.SupportsFloat | typing.SupportsIndex = 0.0, tests: collections.abc.Sequence[str] = [], progress: typing.Any = None) -> BallbarMonteCarlo:
    """
    Monte Carlo check of a joint fit's 1-sigma (ballbar/monte_carlo.hpp).
    
    Parameters
    ----------
    session : the session that was identified
    result : its joint identification
    draws : number of simulated sessions (>= 2); draw k uses seed + k, as simulate_ballbar
    noise_um : 1 sigma of the simulated noise (0: the fit's sigma_um)
    tests : the test labels the fit used (empty: all)
    progress : optional callable(done, total), called after every draw
    
    Returns
    -------
    BallbarMonteCarlo: per observable parameter std_reported, std_mc, ratio, bias; values
    (draws x parameters).
    """
def monte_carlo_probe(session: ProbeSession, result: ProbeIdentification, draws: typing.SupportsInt | typing.SupportsIndex = 100, seed: typing.SupportsInt | typing.SupportsIndex = 1, noise: str = 'auto', progress: typing.Any = None) -> ProbeMonteCarlo:
    """
    Monte Carlo check of a touch-probe joint fit's 1-sigma (probe/monte_carlo.hpp): draw k (seed + k) moves every touch along its direction to the identified machine plus the fit's noise, refitted with `noise` ('auto' or 'white', as the fit was); progress: optional callable(done, total).
    """
def monte_carlo_rtest(session: RtestSession, result: RtestJointIdentification, draws: typing.SupportsInt | typing.SupportsIndex = 100, seed: typing.SupportsInt | typing.SupportsIndex = 1, basis: RtestBasis = ..., progress: typing.Any = None) -> RtestMonteCarlo:
    """
    Monte Carlo check of an R-test joint fit's 1-sigma with the noise model fitted to the session (AR per nest and channel) when the fit used it, else white (rtest/monte_carlo.hpp).
    """
def multi_model_document(identification: MultiIdentification) -> typing.Any:
    """
    The rotacal-model/1 document (kind multi) of one identification from several sessions (rotacal/multi/model_document.hpp).
    """
def noise_ar1(groups: collections.abc.Sequence[str], times: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], rho: typing.SupportsFloat | typing.SupportsIndex, sigma_mm: typing.SupportsFloat | typing.SupportsIndex, seed: typing.SupportsInt | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    ...
def noise_pink(groups: collections.abc.Sequence[str], times: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], sigma_mm: typing.SupportsFloat | typing.SupportsIndex, seed: typing.SupportsInt | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    ...
def noise_probe_zero_wander(groups: collections.abc.Sequence[str], times: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], step_mm: typing.SupportsFloat | typing.SupportsIndex, seed: typing.SupportsInt | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    ...
def noise_thermal_wander(times: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], amplitude_mm: typing.SupportsFloat | typing.SupportsIndex, period_s: typing.SupportsFloat | typing.SupportsIndex, seed: typing.SupportsInt | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    ...
def parse_ballbar_test(label: str, machine: MachineType) -> BallbarTest:
    """
    Test from its session label ('radial_B' only on a BC-trt machine).
    """
def parse_circular_direction(text: str) -> CircularDirection:
    ...
def parse_circular_plane(text: str) -> CircularPlane:
    ...
def parse_machine_type(text: str) -> MachineType:
    """
    A built-in machine by its name ('AC-trt', 'BC-trt', 'B-head-C-table', ...).
    """
def parse_model_document(text: str, source: str = '<model>') -> typing.Any:
    ...
def parse_nc_dialect(text: str) -> NcDialect:
    ...
def parse_radial_side(text: str) -> RadialSide:
    ...
def parse_sweep_direction(text: str) -> SweepDirection:
    ...
def plan_ballbar_test(setup: BallbarSetup = ..., identified: typing.Annotated[numpy.typing.ArrayLike, numpy.float64] | None = None) -> BallbarPlan:
    """
    Plan the single set-up ballbar test (Flynn et al. 2016, Sec. 3).
    
    Parameters
    ----------
    setup : BallbarSetup
    identified : (8,) location errors (mm, rad; order of location_error_names), optional.
        Given, the machine axes are the compensated command for that machine.
    
    Returns
    -------
    BallbarPlan: labels, time (N,), p_table (N, 3), angles_deg (N, 2), machine_axes (N, 5)
    """
def plan_circular_test(plan: CircularTestPlan) -> CircularPlanResult:
    """
    The runs of an ISO 230-4 circular test plan (planes x feeds x directions).
    """
def predict_rtest_session(model: RtestJointModel, session: RtestSession, probe_zeros: collections.abc.Mapping[str, typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]] = {}) -> RtestSession:
    """
    The session with dx,dy,dz predicted by the model and 1-sigma columns dx_std, dy_std, dz_std; probe_zeros (set-up -> (3,) mm) are added if given (rtest/predict.hpp).
    """
def predict_session_lengths(model: BallbarMachineModel, session: BallbarSession) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 1]"]:
    """
    Predicted centre-to-centre lengths (mm) of every sample of the session on the model.
    """
def predict_thermal(model_path: str, duty_path: str, times: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex] | None = None, step_s: typing.SupportsFloat | typing.SupportsIndex = 600.0) -> typing.Any:
    """
    The location errors a thermal model file predicts for a duty (io/thermal_model.hpp).
    
    Parameters
    ----------
    model_path : str
        A thermal model file (``rotacal identify THERMAL.csv --save-model``).
    duty_path : str
        A file of ``# duty.N: TIME, AXIS=SPEED, ...`` lines (from cold at 0 s), or a thermal
        session (its duty and epochs, the lag state 0 at its first row).
    times : list of float, optional
        s on the duty's clock; default every ``step_s`` to 5 taus after the last entry.
    
    Returns
    -------
    dict
        ``axis``, ``times_s``, ``states`` (each lag's y per time) and ``errors``: per location
        error ``name``, ``unit``, ``observable``, ``value`` and ``std`` per time (tau's
        uncertainty propagated with the cold values' and the gains').
    """
def probe_effect_catalogue(machine: MachineType, max_harmonic: typing.SupportsInt | typing.SupportsIndex = 4) -> list[Effect]:
    """
    The catalogue entries of a probe session: effect_catalogue and stylus_radius_offset, probe_lobing.
    """
def probe_model_document(identification: ProbeIdentification, session_name: str) -> typing.Any:
    """
    The rotacal-model/1 document (kind probe) of a joint touch-probe fit (rotacal/probe/model_document.hpp).
    """
def read_ballbar(path: str) -> BallbarSession:
    ...
def read_instrument_session(path: str) -> rotacal._core.BallbarSession | rotacal._core.RtestSession | rotacal._core.ProbeSession:
    """
    Read a ballbar, R-test or touch-probe session (chosen by its format line).
    """
def read_linuxcnc_probe_log(path: str, plan: ProbeSession, max_off_line_mm: typing.SupportsFloat | typing.SupportsIndex = 1.0) -> ProbeSession:
    """
    The session of a LinuxCNC probing log: its latched X Y Z in the plan's rows (probe/nc_program.hpp); a latch farther than max_off_line_mm from its commanded line is refused.
    """
def read_model_document(path: str) -> typing.Any:
    """
    Read a rotacal-model file (strict JSON, version, kind, machine checked); the document as a dict. ParseError (syntax), InvalidArgument (content), IoError.
    """
def read_probe(path: str) -> ProbeSession:
    """
    Read a rotacal-probe/1 file (io/probe_file.hpp).
    """
def read_rtest(path: str) -> RtestSession:
    ...
def read_session(path: str) -> rotacal._core.BallbarSession | rotacal._core.RtestSession:
    """
    Read a rotacal-ballbar/1 or rotacal-rtest/1 file (chosen by its format line).
    """
def realtime_model_of_blob(data: bytes, machine: rotacal._core.MachineType | None = None, source: str = '<blob>') -> RealtimeModel:
    """
    Read a blob (realtime/blob.hpp); ParseError naming the field when it is corrupt, truncated, of another version or (given machine) of another machine.
    """
def realtime_model_of_file(path: str, thermal: bool = False) -> RealtimeModel:
    """
    The real-time model of a model file (io/realtime_export.hpp): every location error and effect; thermal (a model of kind thermal): its cold errors and each lag's gains.
    """
def record_ballbar(port: str, plan: BallbarPlan, path: str, baud: typing.SupportsInt | typing.SupportsIndex = 115200, rate_hz: typing.SupportsFloat | typing.SupportsIndex = 1000.0, zero: bool = False, silence_timeout_s: typing.SupportsFloat | typing.SupportsIndex = 3.0, progress: collections.abc.Callable | None = None) -> RecordSummary:
    """
    Record a ballbar test from a serial port into a rotacal-ballbar/1 file (hw/recorder.hpp). progress(rows, lost, corrupt, t_s, duration_s) -> bool is called a few times a second; returning False stops the recording.
    """
def record_circular_ballbar(port: str, plan: CircularPlanResult, path: str, baud: typing.SupportsInt | typing.SupportsIndex = 115200, rate_hz: typing.SupportsFloat | typing.SupportsIndex = 250.0, zero: bool = False, silence_timeout_s: typing.SupportsFloat | typing.SupportsIndex = 3.0, progress: collections.abc.Callable | None = None) -> RecordSummary:
    """
    Record an ISO 230-4 circular test from a serial port into a rotacal-ballbar/1 file: rows on a data arc labelled with the run (circular_XY_ccw, ...), the rest 'transition' (hw/recorder.hpp); progress as for record_ballbar.
    """
def record_rtest(port: str, mode: str, program: RtestSession, dwell_s: typing.SupportsFloat | typing.SupportsIndex, probe_dirs: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], path: str, baud: typing.SupportsInt | typing.SupportsIndex = 115200, rate_hz: typing.SupportsFloat | typing.SupportsIndex = 100.0, speed: typing.SupportsFloat | typing.SupportsIndex = 1.0, silence_timeout_s: typing.SupportsFloat | typing.SupportsIndex = 3.0, progress: collections.abc.Callable | None = None) -> RecordSummary:
    """
    Record an R-test (sylvac, keyence or stream mode) into a rotacal-rtest/1 file with raw d1,d2,d3 (hw/recorder.hpp); progress as for record_ballbar.
    """
def record_run(nominal: BallbarSession, program: BallbarSession, machine: BallbarMachineModel, seed: typing.SupportsInt | typing.SupportsIndex | None = None, method: str = 'paper', noise_um: typing.SupportsFloat | typing.SupportsIndex = 0.5, noise_rho: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> BallbarSession:
    """
    The session a run records: `program` played on `machine`, AR(1) noise (seed; none if None), recorded against the `nominal` program's X,Y,Z and pivot.
    """
def refuse_disagreeing(identification: MultiIdentification) -> None:
    """
    InvalidArgument naming every disagreement unless there is none or the sigmas were widened for them (multi/model_document.hpp).
    """
@typing.overload
def rtest_error_map(identification: RtestJointIdentification, b_deg: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], c_deg: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], format: str = 'json') -> str:
    """
    The joint model's error map on a grid (deg), as JSON or CSV text.
    """
@typing.overload
def rtest_error_map(identification: RtestPaperIdentification, format: str = 'json') -> str:
    """
    The paper method's error map at its measured grid, as JSON or CSV text.
    """
def rtest_joint_model_document(identification: ..., nests: collections.abc.Mapping[str, typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[3, 1]"]]) -> typing.Any:
    """
    The rotacal-model/1 document (kind rtest-joint) of a joint R-test identification (rotacal/rtest/model_document.hpp); nests: label -> nominal ball centre, mm.
    """
def rtest_map_names(machine: MachineType) -> list[str]:
    """
    Names of a machine's two R-test error maps, [tilt axis' map, rotary axis' map], e.g. ['BY', 'CB'] on BC-trt, ['BZ', 'CY'] on B-head-C-table.
    """
def rtest_prediction_rms_um(model: RtestJointModel, session: RtestSession) -> float:
    """
    RMS (um) of measured - predicted readings after one constant offset per set-up.
    """
def rtest_readings(machine: MachineType, errors: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], effects: collections.abc.Sequence[str], effect_params: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], q: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], angles: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], time: typing.Annotated[numpy.typing.ArrayLike, numpy.float64, "[m, 1]"], linear_reference: typing.Annotated[numpy.typing.ArrayLike, numpy.float64] | None = None) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]:
    """
    Noise-free readings (N, 3) of the nest at q (mm) at angles (N, 2) in rad and time (N,) s, no probe zero: the simulator's truth. linear_reference (3,) mm: the session's mean commanded xyz, about which the linear-axis polynomials are taken (None: the mean of these poses).
    """
def run_label(test: BallbarTest, direction: SweepDirection, feed_factor: typing.SupportsFloat | typing.SupportsIndex, setup: ...) -> str:
    """
    Label of one run: test label, '_cw', '_f<feed>'.
    """
def simulate_ballbar(commanded: BallbarSession, truth: BallbarMachineModel, noise_um: typing.SupportsFloat | typing.SupportsIndex = 0.5, seed: typing.SupportsInt | typing.SupportsIndex = 1, declare_noise: bool = True) -> BallbarSession:
    """
    The session as the machine `truth` would measure it (lengths filled in, Gaussian noise).
    """
def simulate_circular(plan: CircularPlanResult, options: CircularSimulationOptions) -> BallbarSession:
    """
    The session a ballbar records on a machine with linear-axis errors.
    """
def simulate_probe(machine: MachineType, errors: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], effects: collections.abc.Sequence[str] = [], effect_params: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex] = [], sphere_offset: typing.Annotated[numpy.typing.ArrayLike, numpy.float64] = ..., noise_um: typing.SupportsFloat | typing.SupportsIndex = 0.5, ar1_rho: typing.SupportsFloat | typing.SupportsIndex = 0.0, seed: typing.SupportsInt | typing.SupportsIndex = 1, poses_deg: typing.Annotated[numpy.typing.ArrayLike, numpy.float64] | None = None, directions: typing.Annotated[numpy.typing.ArrayLike, numpy.float64] | None = None, sphere: typing.Annotated[numpy.typing.ArrayLike, numpy.float64] = ..., sphere_diameter: typing.SupportsFloat | typing.SupportsIndex = 25.0, stylus_diameter: typing.SupportsFloat | typing.SupportsIndex = 6.0, pose_directions: collections.abc.Sequence[typing.Annotated[numpy.typing.ArrayLike, numpy.float64]] = []) -> tuple[ProbeSession, typing.Annotated[numpy.typing.NDArray[numpy.float64], "[3, 1]"]]:
    """
    Simulate a touch-probe session (probe/simulate.hpp): (session, actual sphere centre). Poses default to default_probe_pattern's.
    """
def simulate_probe_calibration(dirs: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], zeros: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], moves: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], noise_um: typing.SupportsFloat | typing.SupportsIndex, seed: typing.SupportsInt | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]:
    """
    Simulated readings (N, 3) of the direction calibration.
    """
def simulate_rtest(machine: MachineType, errors: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], effects: collections.abc.Sequence[str], effect_params: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], b_deg: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], c_deg: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], nests: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], dwell_s: typing.SupportsFloat | typing.SupportsIndex, noise_um: typing.SupportsFloat | typing.SupportsIndex, probe_zero_um: typing.SupportsFloat | typing.SupportsIndex, probe_dirs: typing.Annotated[numpy.typing.ArrayLike, numpy.float64] | None = None, write_d: bool = True, seed: typing.SupportsInt | typing.SupportsIndex = 1) -> tuple[RtestSession, typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]]:
    """
    Simulate an R-test session (rtest/simulate.hpp).
    
    Parameters
    ----------
    machine : MachineType (any; the pattern must fit its limits: default_rtest_pattern)
    errors : (8,) location errors (mm, rad)
    effects, effect_params : catalogue ids and their parameters back to back
    b_deg, c_deg : the grid, tilt axis outer and rotary axis inner (deg)
    nests : (K, 3) nominal ball centres, table frame (mm)
    dwell_s : time between readings (s)
    noise_um, probe_zero_um : 1-sigma reading noise and per-set-up probe zero (um)
    probe_dirs : (3, 3) rows = probe directions: raw d1,d2,d3 are written as well
    write_d : with probe_dirs, also write dx,dy,dz
    
    Returns
    -------
    (session, probe_zeros (K, 3) mm)
    """
def simulate_spindle_indexing(dirs: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], zeros: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], offset: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], centre: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], angles: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], noise_um: typing.SupportsFloat | typing.SupportsIndex, seed: typing.SupportsInt | typing.SupportsIndex) -> typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]:
    """
    Simulated spindle-indexing readings (N, 3), mm.
    """
def simulate_thermal(instrument: str, machine: MachineType, errors: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], effects: collections.abc.Sequence[str], effect_params: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], duty: collections.abc.Sequence[tuple[typing.SupportsFloat | typing.SupportsIndex, collections.abc.Mapping[str, typing.SupportsFloat | typing.SupportsIndex]]], epoch_start_s: collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], axis: str, lags: collections.abc.Sequence[tuple[typing.SupportsFloat | typing.SupportsIndex, typing.Annotated[numpy.typing.ArrayLike, numpy.float64], typing.Annotated[numpy.typing.ArrayLike, numpy.float64]]], poses_deg: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], noise_um: typing.SupportsFloat | typing.SupportsIndex, ar1_rho: typing.SupportsFloat | typing.SupportsIndex, seed: typing.SupportsInt | typing.SupportsIndex, table_points: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], sphere_offset: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], probe_zero_um: typing.SupportsFloat | typing.SupportsIndex, dwell_s: typing.SupportsFloat | typing.SupportsIndex) -> tuple[typing.Any, list[int], typing.Annotated[numpy.typing.NDArray[numpy.float64], "[m, 3]"]]:
    """
    Simulate a thermal probe or R-test session on rotacal's own simulators.
    
    The pattern (``poses_deg``, (N, 2) tilt and rotary angles in deg) is measured once per epoch
    from each of ``epoch_start_s``; between and during them the location errors and the
    table-side points drift as ``thermal_location_R`` of ``axis`` (effects.md) driven by ``duty``
    (``[(time_s, {axis: rev/min})]``), one or two ``lags`` of (tau_s, 8 gains, 3 point gains).
    
    Parameters
    ----------
    instrument : str
        "probe" (``table_points``: the nominal sphere centre, ``sphere_offset`` its set-up error)
        or "rtest" (``table_points``: the nests, each mounted through the session).
    noise_um, ar1_rho : float
        1-sigma noise per coordinate or reading; its AR(1) correlation from row to row.
    
    Returns
    -------
    tuple
        (session, each row's epoch, the probe's actual sphere centre or the R-test's probe zeros).
    """
def sinumerik_eec_tables(model_path: str, spacing_deg: typing.SupportsFloat | typing.SupportsIndex = 5.0, range_deg: collections.abc.Mapping[str, typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(2)"]] = {}, axis_names: collections.abc.Mapping[str, str] = {}, max_points: typing.SupportsInt | typing.SupportsIndex = 0, generated_at: str = '') -> CompensationTables:
    """
    SINUMERIK EEC programs ($AA_ENC_COMP) of each table axis' positioning error (io/compensation_table.hpp); max_points 0: 200 (808D), else MD38000 as configured.
    """
def sinumerik_tables(model_path: str, spacing_deg: typing.SupportsFloat | typing.SupportsIndex = 5.0, range_deg: collections.abc.Mapping[str, typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(2)"]] = {}, axis_names: collections.abc.Mapping[str, str] = {}, max_points: typing.SupportsInt | typing.SupportsIndex = 0, max_cross_points: typing.SupportsInt | typing.SupportsIndex = 0, generated_at: str = '') -> CompensationTables:
    """
    SINUMERIK EEC programs of each table axis' positioning error and CEC programs of its translations (io/compensation_table.hpp); max_points 0: 200, else MD38000; max_cross_points 0: 200, else MD18342.
    """
def sphere_fit(points: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], radius: typing.SupportsFloat | typing.SupportsIndex | None = None, sigma: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> SphereFit:
    """
    Least-squares sphere to (N, 3) points; radius fixes it (e.g. the ballbar length).
    """
def svd_plane_fit(points: typing.Annotated[numpy.typing.ArrayLike, numpy.float64], normal_hint: typing.Annotated[numpy.typing.ArrayLike, numpy.float64] = ..., sigma: typing.SupportsFloat | typing.SupportsIndex = 0.0) -> PlaneFit:
    """
    Total-least-squares plane (Flynn et al. Eq. 3).
    """
def table_motion_overlap(machine: MachineType, a: str, b: str, tilt_limits_deg: typing.Annotated[collections.abc.Sequence[typing.SupportsFloat | typing.SupportsIndex], "FixedSize(2)"] = [-90.0, 90.0], duration_s: typing.SupportsFloat | typing.SupportsIndex = 3600.0, reference_radius_mm: typing.SupportsFloat | typing.SupportsIndex = 100.0) -> TableMotionOverlap:
    """
    Compare the table motions of effects a and b (catalogue ids) on a machine.
    """
def test_label(test: BallbarTest, machine: MachineType) -> str:
    """
    Session label of a test on a machine, e.g. 'radial_A'.
    """
def uncertainty_budget_ballbar(session: BallbarSession, diagnosis: ..., sizes: PlausibleSizes = ..., coverage: typing.SupportsFloat | typing.SupportsIndex = 0.95) -> UncertaintyBudget:
    """
    GUM budget of the location errors of diagnose_ballbar's result.
    """
def uncertainty_budget_probe(session: ProbeSession, diagnosis: Diagnosis, sizes: PlausibleSizes = ..., coverage: typing.SupportsFloat | typing.SupportsIndex = 0.95) -> UncertaintyBudget:
    """
    GUM budget of the location errors of diagnose_probe's result (the probe's entries: stylus calibration, lobing).
    """
def uncertainty_budget_rtest(session: RtestSession, diagnosis: ..., sizes: PlausibleSizes = ..., coverage: typing.SupportsFloat | typing.SupportsIndex = 0.95) -> UncertaintyBudget:
    """
    GUM budget of the location errors of diagnose_rtest's result.
    """
def uncertainty_budget_rtest_identification(session: RtestSession, identification: ..., sizes: PlausibleSizes = ..., coverage: typing.SupportsFloat | typing.SupportsIndex = 0.95) -> UncertaintyBudget:
    """
    GUM budget of the location errors of identify_rtest_joint's result, on its own model (maps included).
    """
def verify_compensation(commanded: BallbarSession, truth: BallbarMachineModel, noise_um: typing.SupportsFloat | typing.SupportsIndex = 0.5, seed: typing.SupportsInt | typing.SupportsIndex = 1) -> CompensationReport:
    """
    Measure, identify, compensate, measure again, identify again (Flynn et al., Table 2).
    """
def write_ballbar(session: BallbarSession, path: str) -> None:
    ...
def write_circular_nc_program(plan: CircularPlanResult, dialect: NcDialect, options: NcProgramOptions = ...) -> str:
    """
    NC program text of a circular plan.
    """
def write_model_document(document: dict, path: str, inputs: collections.abc.Sequence[str] = [], other_outputs: collections.abc.Sequence[str] = []) -> None:
    ...
@typing.overload
def write_nc_program(plan: BallbarPlan, dialect: NcDialect, options: NcProgramOptions = ...) -> str:
    """
    NC program text: 'linuxcnc' machine axes (G93 G1), or TCP programs for 'heidenhain' (FUNCTION TCPM), 'siemens' (TRAORI), 'fanuc' (G43.4).
    """
@typing.overload
def write_nc_program(plan: BallbarPlan, dialect: str, options: NcProgramOptions = ...) -> str:
    ...
def write_output(path: str, data: bytes, inputs: collections.abc.Sequence[str] = [], other_outputs: collections.abc.Sequence[str] = []) -> None:
    """
    Write bytes to path: regular files replaced atomically, devices and FIFOs written through; a directory, an input or another output is refused (IoError).
    """
def write_probe(session: ProbeSession, path: str) -> None:
    ...
def write_probe_nc_program(machine: MachineType, dialect: str, poses_deg: typing.Annotated[numpy.typing.ArrayLike, numpy.float64] | None = None, sphere: typing.Annotated[numpy.typing.ArrayLike, numpy.float64] = ..., sphere_diameter: typing.SupportsFloat | typing.SupportsIndex = 25.0, stylus_diameter: typing.SupportsFloat | typing.SupportsIndex = 6.0, log_file: str = 'rotacal_probe.log', tool: typing.SupportsInt | typing.SupportsIndex = 1, decimals: typing.SupportsInt | typing.SupportsIndex = 4, approach_mm: typing.SupportsFloat | typing.SupportsIndex = 5.0, probe_feed: typing.SupportsFloat | typing.SupportsIndex = 50.0, positioning_feed: typing.SupportsFloat | typing.SupportsIndex = 1000.0, pose_directions: collections.abc.Sequence[typing.Annotated[numpy.typing.ArrayLike, numpy.float64]] = [], thermal: tuple[str, typing.SupportsFloat | typing.SupportsIndex, typing.SupportsFloat | typing.SupportsIndex, typing.SupportsFloat | typing.SupportsIndex, typing.SupportsFloat | typing.SupportsIndex, typing.SupportsFloat | typing.SupportsIndex] | None = None) -> str:
    """
    The probing program of the default pattern's directions (or each pose's `pose_directions`, (K_i, 3)) at `poses_deg` (default: its poses) (probe/nc_program.hpp); linuxcnc only. approach_mm: the G38.2 starts this far outside the trigger sphere; probe_feed: its feed, positioning_feed: the G1 moves' to and from its start, mm/min. thermal: (axis, speed rev/min, heat s, cool s, interval s, max speed rev/min), the pattern as one epoch per interval and the duty between (ThermalProgramDuty).
    """
def write_rtest(session: RtestSession, path: str) -> None:
    ...
