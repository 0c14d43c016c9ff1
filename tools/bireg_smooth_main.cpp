// The bireg_smooth executable: the tool is bireg_cli::smooth_main (bireg_smooth.cpp).
#include "entry_points.hpp"

int main(int argc, char** argv) {
  return bireg_cli::smooth_main(argc, argv);
}
