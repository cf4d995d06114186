/* Stub of MBsysC's project interface (no callbacks in the timed functions). */
#include "mbs_data.h"
