#include "planarvo/planarvo.h"

extern "C" {
PLANARVO_API int planarvo_version_number(void) { return PLANARVO_VERSION_NUMBER; }
PLANARVO_API const char* planarvo_version_string(void) { return PLANARVO_VERSION_STRING; }
}
