/* Stub of Robotran 7's function header (nothing needed). */
#include "mbs_data.h"
