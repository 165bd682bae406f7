/* Links against an installed planarvo and checks that header and library agree. */
#include <planarvo/planarvo.h>
#include <stdio.h>

int main(void) {
  if (planarvo_version_number() != PLANARVO_VERSION_NUMBER) {
    fprintf(stderr, "header %d, library %d\n", PLANARVO_VERSION_NUMBER, planarvo_version_number());
    return 1;
  }
  printf("planarvo %s\n", planarvo_version_string());
  return 0;
}
