// SPDX-License-Identifier: BSD-3-Clause
// The tests' precompiled header is built by an object library (tests/CMakeLists.txt), which
// CMake requires to have a source file: this one, empty.
