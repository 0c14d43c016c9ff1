// bireg: kernel-weighted local geodesic regression (DESIGN.md section 5):
// the estimator (statistics/local_geodesic.hpp), its windows
// (statistics/local_window.hpp), kernels (statistics/kernel.hpp) and the
// automatic bandwidth (statistics/bandwidth.hpp).
#pragma once

#include "bireg/statistics/bandwidth.hpp"
#include "bireg/statistics/kernel.hpp"
#include "bireg/statistics/local_geodesic.hpp"
#include "bireg/statistics/local_window.hpp"
