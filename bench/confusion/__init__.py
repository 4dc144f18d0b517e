# SPDX-License-Identifier: BSD-3-Clause
"""Helpers of bench/diagnosis_confusion.py: refsim sessions and Jacobians (setup), statistics
and the oracle (stats), classification of rotacal's findings (outcome), tables (report)."""
