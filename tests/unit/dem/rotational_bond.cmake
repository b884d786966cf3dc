# Rotational (6-DOF) bond unit test; included from tests/unit/dem/CMakeLists.txt.
fracflow_test(test_rotational_bond SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_rotational_bond.cpp LIBS fracflow_core)
