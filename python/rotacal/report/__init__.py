# SPDX-License-Identifier: BSD-3-Clause
"""Self-contained HTML reports (no network needed to open them): set-up, location errors in
an ISO 230-7 style table, ballbar polar plots of measured against model with the deviation
magnified, R-test error maps, residual plots, and the diagnosis with before/after plots.

Modules: page (the HTML page, figures as data URIs), sections (what every report shares),
ballbar, rtest, circular, probe (each instrument's page; probe also the joint page of several sessions). Importing this package loads matplotlib.
"""

from .ballbar import ballbar_report, extended_identification, location_errors_section, polar_plots  # noqa: F401
from .circular import circular_report  # noqa: F401
from .probe import multi_report, probe_report  # noqa: F401
from .rtest import rtest_b_map_plot, rtest_c_map_plot, rtest_report, rtest_residual_plot  # noqa: F401
from .sections import (
    CONFIGURATION_WORDS,
    ERROR_WORDS,
    diagnosis_report,
    diagnosis_section,  # noqa: F401
    error_words,
    fitted_effects_table,
    harmonic_plot,
    location_error_table,
    machine_words,
    noise_budget_section,
    residual_plot,
)
