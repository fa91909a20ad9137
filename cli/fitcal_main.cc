// fitcal: offline calibration of wheeled odometry. The subcommands, their flags and the process's
// setup are in cli/command_line.cc (compiled with the other command files).

#include "cli/command_line.h"

int main(int argc, char** argv) { return fitcal::tools::RunCommandLine(argc, argv); }
