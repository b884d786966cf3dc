# Packing files (src/dem/packing_file.*, benchmarks/dem_ucs --packing); included from
# tests/unit/dem/CMakeLists.txt.
fracflow_test(test_packing_file SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_packing_file.cpp LIBS fracflow_dem fracflow_io)
