// The effects' entry points for the library's scalars, compiled once here
// (include/rotacal/kinematics/effects_instances.hpp).
#include "rotacal/kinematics/effects_instances.hpp"

namespace rotacal {
ROTACAL_EFFECTS_SCALARS(ROTACAL_EFFECTS_INSTANCES, )
}  // namespace rotacal
