// bireg: everything at once (the groups, the concept, geodesics and the
// regression). Including only what you use compiles faster.
#pragma once

#include "bireg/concept.hpp"
#include "bireg/geodesic.hpp"
#include "bireg/groups/matrix_group.hpp"
#include "bireg/groups/product.hpp"
#include "bireg/groups/rn.hpp"
#include "bireg/groups/se2.hpp"
#include "bireg/groups/se3.hpp"
#include "bireg/groups/sim3.hpp"
#include "bireg/groups/so2.hpp"
#include "bireg/groups/so3.hpp"
#include "bireg/regression.hpp"
