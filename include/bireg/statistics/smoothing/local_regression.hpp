// bireg: kernel-weighted local geodesic regression (DESIGN.md section 5):
// the estimator (statistics/smoothing/local_geodesic.hpp), its windows
// (statistics/smoothing/local_window.hpp), kernels (statistics/smoothing/kernel.hpp) and the
// automatic bandwidth (statistics/smoothing/bandwidth.hpp).
#pragma once

#include "bireg/statistics/smoothing/bandwidth.hpp"
#include "bireg/statistics/smoothing/kernel.hpp"
#include "bireg/statistics/smoothing/local_geodesic.hpp"
#include "bireg/statistics/smoothing/local_window.hpp"
