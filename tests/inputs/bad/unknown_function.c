//
//	ROBOTRAN - Version 6.6 (build : february 22, 2008)
//
#include <math.h> 
#include "mbs_data.h"

void mbs_invdyna(double *Qq,
MbsData *s, double tsim)
{ 
#define q s->q 
#define qd s->qd 
#define qdd s->qdd 

  C1 = cos(q[1]);
  S1 = sin(q[1]);
  AF1 = s->g[3]*tan(q[1]);
  Qq[1] = AF1;
}
