"""Print the numpy SIMD features that ``make test-full`` switches off
(``NPY_DISABLE_CPU_FEATURES``) to run the check as a CPU with narrower
vector units would: every dispatched feature this CPU has above the lowest
one (an AVX-512 machine then runs numpy's AVX2 loops, as an AMD Zen 3 does),
or that lowest one alone on a CPU that has nothing above it (it then runs the
baseline loops). Prints nothing when numpy dispatches nothing here.
"""
import numpy._core._multiarray_umath as umath

found = [f for f in umath.__cpu_dispatch__ if umath.__cpu_features__.get(f)]
print(" ".join(found[1:] or found))
