// SPDX-License-Identifier: BSD-3-Clause
// The effects' entry points for the library's scalars, compiled once here
// (include/rotacal/kinematics/effects_instances.hpp), and the stages the diagnosis' chain rule
// calls (stage_instances.hpp).
#include "rotacal/kinematics/effects_instances.hpp"

#include "stage_instances.hpp"

namespace rotacal {
ROTACAL_EFFECTS_SCALARS(ROTACAL_EFFECTS_INSTANCES, )
ROTACAL_STAGE_SCALARS()
}  // namespace rotacal
