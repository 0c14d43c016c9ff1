// The bireg_fit executable: the tool is bireg_cli::fit_main (bireg_fit.cpp).
#include "entry_points.hpp"

int main(int argc, char** argv) {
  return bireg_cli::fit_main(argc, argv);
}
