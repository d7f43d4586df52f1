/* Status names and messages, generated from OBS_STATUS_MAP. */
#include "obscura/obscura.h"

const char *obs_status_name(obs_status s)
{
    switch (s) {
#define X(name, msg) case OBS_##name: return #name;
        OBS_STATUS_MAP(X)
#undef X
    default: return "UNKNOWN";
    }
}

const char *obs_status_message(obs_status s)
{
    switch (s) {
#define X(name, msg) case OBS_##name: return msg;
        OBS_STATUS_MAP(X)
#undef X
    default: return "unknown status";
    }
}
