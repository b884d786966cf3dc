# Flexible-wall membrane unit tests (src/dem/membrane); included from tests/unit/dem/CMakeLists.txt.
fracflow_test(test_membrane SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_membrane.cpp LIBS fracflow_dem)
