#include "planarvo/planarvo.h"
extern "C" {
PLANARVO_API void planarvo_sim_options_init(planarvo_sim_options*) {}
PLANARVO_API planarvo_status planarvo_simulate(planarvo_context*, const planarvo_sim_options*, const char*) { return PLANARVO_ERROR_INTERNAL; }
}
