# Whole-program tests: the default case end to end, and the quick validation of each thesis
# case (coarse resolutions; `rktsph validate --full` runs the acceptance resolutions). Each runs
# on one thread so that CTest can run two of them side by side on a 2-core machine.
add_test(NAME run_default_case
         COMMAND rktsph run ${PROJECT_SOURCE_DIR}/cases/thesis/01_elastic_bar_1d.toml
                 --out ${CMAKE_BINARY_DIR}/test-out/case01 --quiet --threads 1)
set_tests_properties(run_default_case PROPERTIES LABELS integration)

set(RKTSPH_VALIDATION_CASES 01 02 03 04 05 06 07 08 09 10 11 12 13 14 15 16 17 mandel)
foreach(case_id IN LISTS RKTSPH_VALIDATION_CASES)
  add_test(NAME validate_quick_${case_id}
           COMMAND rktsph validate --quick ${case_id} --threads 1
                   --out ${CMAKE_BINARY_DIR}/validation/quick_${case_id})
  set_tests_properties(validate_quick_${case_id} PROPERTIES LABELS validation TIMEOUT 1500)
endforeach()

# Fuzz test of the input reading (scripts/fuzz_inputs.py): 4000 mutated thesis-case and
# material-point files through the binary, each a few steps long; every outcome must be exit 0,
# 2 with the file and a line or key named, or 3 with a solver diagnosis; never a crash, a hang or
# an uncaught error. A fixed seed: a failure prints the input's number and how to rerun it.
# About 27 s with its two jobs on a 2-core machine; PROCESSORS 2 keeps ctest -j 2 from running
# another test beside it.
add_test(NAME fuzz_inputs
         COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/scripts/fuzz_inputs.py --binary $<TARGET_FILE:rktsph>
                 --count 4000 --seed 14 --jobs 2 --timeout 120 --work ${CMAKE_BINARY_DIR}/test-out/fuzz)
set_tests_properties(fuzz_inputs PROPERTIES LABELS fuzz PROCESSORS 2 TIMEOUT 900)

# `rktsph fos` (docs/fos.md) on Case 5's cut at the quick spacing 0.5 m, tolerance 2 %, two trials
# at once: gamma H / c_F = 3.4 F must lie in the limit-analysis bracket [3.64, 4.00] of cases.md
# Case 5. 6 trials in 3 rounds; about 50 s on a 2-core machine (PROCESSORS 2: it uses both).
add_test(NAME fos_quick
         COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/scripts/check_fos.py --binary $<TARGET_FILE:rktsph>
                 --case ${PROJECT_SOURCE_DIR}/cases/thesis/05_viscoplastic_cut_2d.toml
                 --out ${CMAKE_BINARY_DIR}/test-out/fos_quick --scale 3.4 --low 3.64 --high 4.00
                 -- --set geometry.spacing=0.5 --tol 0.02 --jobs 2 --threads 2 --quiet)
set_tests_properties(fos_quick PROPERTIES LABELS validation PROCESSORS 2 TIMEOUT 600)

# Every case file shipped under cases/ is sound: `rktsph check` reads it as `run` (or
# `material-point`) would and builds its particles and solver, without running it. A key renamed
# or a default changed without updating the files fails here, not in a user's run. Under a second.
file(GLOB RKTSPH_SHIPPED_CASES CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/cases/*/*.toml)
add_test(NAME shipped_case_files COMMAND rktsph check ${RKTSPH_SHIPPED_CASES})
set_tests_properties(shipped_case_files PROPERTIES LABELS integration)
