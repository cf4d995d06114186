//
//-------------------------------------------------------------
//
//	ROBOTRAN - Version 6.6 (build : february 22, 2008)
//
//	==> Project name : seed_eq21
//	==> The eight equations of the seed's eq. 2.1 (AF24 ... OM26), written by the robovec
//	==> project as a Robotran C file; qp(i) of the seed is qd[i] here. Outputs Qq[1..8] hand
//	==> the eight values back.
//
//-------------------------------------------------------------
//
 
#include <math.h> 

#include "mbs_data.h"
#include "mbs_project_interface.h"
 
void mbs_invdyna(double *Qq,
MbsData *s, double tsim)

// double Qq[8];
{ 
#define q s->q 
#define qd s->qd 
#define qdd s->qdd 

// Trigonometric Variables  

  C4 = cos(q[4]);
  S4 = sin(q[4]);
  C5 = cos(q[5]);
  S5 = sin(q[5]);
  C6 = cos(q[6]);
  S6 = sin(q[6]);

// = = Block_0_1_0_0_0_1 = = 
 
  AF24 = -s->g[3]*S4;
  AF34 = -s->g[3]*C4;
  OM15 = qd[4]*C5;
  OM35 = qd[4]*S5;
  AF15 = -AF34*S5;
  AF35 = AF34*C5;
  OM16 = qd[5]*S6+OM15*C6;
  OM26 = qd[5]*C6-OM15*S6;

// Symbolic Outputs  

  Qq[1] = AF24;
  Qq[2] = AF34;
  Qq[3] = OM15;
  Qq[4] = OM35;
  Qq[5] = AF15;
  Qq[6] = AF35;
  Qq[7] = OM16;
  Qq[8] = OM26;

// ====== END Task 0 ====== 

}
 
