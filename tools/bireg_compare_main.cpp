// The bireg_compare executable: the tool is bireg_cli::compare_main (bireg_compare.cpp).
#include "entry_points.hpp"

int main(int argc, char** argv) {
  return bireg_cli::compare_main(argc, argv);
}
