// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Levinson's recursion, shared by the AR estimate (noise_model.cpp) and the AR prewhitener and
// covariances (ar_whitener.cpp).
#include <vector>

namespace rotacal::noise_detail {

// Levinson: prediction coefficients of every order 0..p from the reflection coefficients
// (phi_{m,m} = k_m, phi_{m,j} = phi_{m-1,j} - k_m phi_{m-1,m-j}).
std::vector<std::vector<double>> levinson(const std::vector<double>& k);

}  // namespace rotacal::noise_detail
