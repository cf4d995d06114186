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
  NRh2 = 1.0;
  while((NRh2 > 0.001))
  {
  NRh2 = NRh2*S1;
  }
  Qq[1] = NRh2;
}
