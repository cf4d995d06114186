%	ROBOTRAN - Version 6.6 (build : february 22, 2008)
function [Qq] = invdyna(s,tsim,usrfun)

 Qq = zeros(2,1);

q = s.q; 

  C1 = cos(q(1));
  AF1 = s.g(3)*atan2(C1,q(1));
  Qq(1) = AF1;
