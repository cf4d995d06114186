#	MBsysTran - Release 8.1

from math import sin, cos

def invdyna(phi,s,tsim):
    Qq = phi  # compatibility with symbolic generation
    q = s.q

    C1 = cos(q[1])
    AF1 = s.g[3]*BF7
    Qq[1] = AF1
