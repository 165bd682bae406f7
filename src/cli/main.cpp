// The `planarvo` command-line tool: a client of the C API (include/planarvo/planarvo.h) only.
#include <cstdio>

#include "planarvo/planarvo.h"

int main(int argc, char** argv) {
  (void)argc;
  (void)argv;
  std::printf("planarvo %s\n", planarvo_version_string());
  return 0;
}
