# Seed 004's cohesive contact law (src/dem/bond/cohesive_bond.hpp); included from tests/unit/dem/CMakeLists.txt.
fracflow_test(test_cohesive_law SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_cohesive_law.cpp LIBS fracflow_dem)
