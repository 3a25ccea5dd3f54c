# Whole-program tests: the default case end to end, and the quick validation of each thesis
# case (coarse resolutions; `rktsph validate --full` runs the acceptance resolutions). Each runs
# on one thread so that CTest can run two of them side by side on a 2-core machine.
add_test(NAME run_default_case
         COMMAND rktsph run ${PROJECT_SOURCE_DIR}/cases/thesis/01_elastic_bar_1d.toml
                 --out ${CMAKE_BINARY_DIR}/test-out/case01 --quiet --threads 1)
set_tests_properties(run_default_case PROPERTIES LABELS integration)

set(RKTSPH_VALIDATION_CASES 01 02 03 04 05 06 07 13 14 15 16 17)
foreach(case_id IN LISTS RKTSPH_VALIDATION_CASES)
  add_test(NAME validate_quick_${case_id}
           COMMAND rktsph validate --quick ${case_id} --threads 1
                   --out ${CMAKE_BINARY_DIR}/validation/quick_${case_id})
  set_tests_properties(validate_quick_${case_id} PROPERTIES LABELS validation TIMEOUT 1500)
endforeach()
