// dummy: a point with an orientation (V-REP's dummy): a reference frame, an
// IK tip or target, a plugin sensor's mount. No rows.
#include "framework/object_type.h"
#include "framework/types/core_types.h"

namespace swarmsim {

constinit const ObjectTypeDescriptor kDummyType{
    .name = "dummy",
    .description = "a reference frame: IK tips and targets, mounting points",
};

}  // namespace swarmsim
