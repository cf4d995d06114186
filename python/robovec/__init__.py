"""robovec from Python (docs/python.md).

    import robovec
    m = robovec.load("robot.urdf", free_flyer=True)   # or a Robotran .c/.m/.py, or .rvir
    m.functions                                       # ['invdyna', 'dirdyna', 'fordyna']
    r = m.run("atomise,default<ops>")                 # a new module: r.ir, r.report
    robovec.passes()                                  # the registry, as --print-passes
    rnea = m.compile("rnea", pipeline="default<ops>", batch=4, trig="inline")
    tau = rnea(q, v, a)                               # (nq,), (nv,), (nv,) -> (nv,); (B, n) -> (B, nv)

Every operation is a run of the command line's own code, so its errors are the command line's:
UsageError (exit status 2), InputError (exit status 1; `file`, `line`, `column` when the
diagnostic names a place), TimeLimitError (an InputError), all robovec.Error.
"""

from ._robovec import (  # noqa: F401
    Compiled,
    Error,
    InputError,
    Module,
    TimeLimitError,
    UsageError,
    load,
    passes,
)

__all__ = ["load", "passes", "Module", "Compiled", "Error", "UsageError", "InputError", "TimeLimitError"]
