# Whole-program tests: the default case end to end, and the quick validation of the thesis
# cases (coarse resolutions; `rktsph validate --full` runs the acceptance resolutions).
add_test(NAME run_default_case
         COMMAND rktsph run ${PROJECT_SOURCE_DIR}/cases/thesis/01_elastic_bar_1d.toml
                 --out ${CMAKE_BINARY_DIR}/test-out/case01 --quiet)
set_tests_properties(run_default_case PROPERTIES LABELS integration)
add_test(NAME validate_quick
         COMMAND rktsph validate --quick --out ${CMAKE_BINARY_DIR}/validation)
set_tests_properties(validate_quick PROPERTIES LABELS validation TIMEOUT 1500)
