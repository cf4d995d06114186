/* Stub of Robotran 7's data structure header: the benchmark's MbsData. */
#include "mbs_data.h"
