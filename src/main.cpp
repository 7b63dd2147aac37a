// rwcalc: the executable is a thin wrapper around the library's command-line front end.
#include <iostream>

#include "rwcalc/cli.hpp"

int main(int argc, char** argv) { return rwcalc::cli::run(argc, argv, std::cout, std::cerr); }
