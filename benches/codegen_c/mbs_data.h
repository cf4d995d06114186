/* Minimal MbsData for timing Robotran's generated C in robovec's benchmark (benches/codegen_c.rs).
 * Only the fields Robotran's dirdyna/invdyna read; arrays are 1-based as in MBsysC, sized by the
 * harness. Not MBsysC's definition: written for this benchmark. */
#ifndef ROBOVEC_BENCH_MBS_DATA_H
#define ROBOVEC_BENCH_MBS_DATA_H
typedef struct MbsData {
    double *q, *qd, *qdd, *m, *g, *Qq;
    double **l, **In, **dpt, **frc, **trq;
    double tsim;
} MbsData;
typedef MbsData MBSdataStruct;
#endif
