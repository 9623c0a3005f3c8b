/* cellmap-serve: `cellmap serve` as a program of its own, which `cellmap
 * serve` runs (src/cmd_serve.c says why). */
#include "src/commands.h"

int main(int argc, char **argv) { return cmd_serve(argc, argv); }
