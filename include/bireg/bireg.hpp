// bireg: everything at once. Include single headers instead to compile only
// what you use (each is self-contained).
#pragma once

#include "bireg/core/bernoulli.hpp"
#include "bireg/core/concept.hpp"
#include "bireg/core/exact_inverse_differential.hpp"
#include "bireg/core/inverse_differential.hpp"
#include "bireg/core/small_angle.hpp"
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
