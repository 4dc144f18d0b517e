# SPDX-License-Identifier: BSD-3-Clause
"""The version of the rotacal package (a leaf module: the report and the model files quote it
without importing the package)."""

__version__ = "0.1.0"
