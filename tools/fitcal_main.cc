// fitcal: offline calibration of wheeled odometry. The subcommands, their flags and the process's
// setup are in tools/command_line.cc (compiled with the other command files).

#include "tools/command_line.h"

int main(int argc, char** argv) { return fitcal::tools::RunCommandLine(argc, argv); }
