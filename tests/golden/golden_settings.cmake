# The one place that states how golden images are rendered and judged; read by
# tests/golden/CMakeLists.txt, run_golden.cmake and scripts/update-golden.sh.
#
# Renders are deterministic (counter-based random numbers), so on the machine
# that made the references the error is 0. The tolerance only has to absorb
# floating-point differences between compilers and CPUs (relative ~1e-6 per
# pixel), while any real change (another seed, sun, camera, material, a bug in
# the integrator) moves the Monte Carlo noise of every pixel and the relMSE by
# orders of magnitude more; tests/golden checks that a different seed fails.
set(GOLDEN_SIZE 160x90)
set(GOLDEN_SPP 16)
set(GOLDEN_METRIC relmse)       # mean (a-b)^2 / (b^2 + 1e-2) over pixels and R,G,B
set(GOLDEN_THRESHOLD 1e-5)      # global relMSE allowed (a new seed at sunset gives ~1e-4)
set(GOLDEN_PIXEL_THRESHOLD 1e-2)  # per-pixel relative squared error ...
set(GOLDEN_FAIL_PERCENT 1)        # ... exceeded by at most 1 % of the pixels
