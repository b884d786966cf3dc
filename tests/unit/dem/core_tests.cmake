# DEM core unit tests (contact laws, parallel bond, neighbour list, DemSystem); included from
# tests/unit/dem/CMakeLists.txt.
fracflow_test(test_contact_laws SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_contact_laws.cpp LIBS fracflow_dem)
fracflow_test(test_parallel_bond SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_parallel_bond.cpp LIBS fracflow_dem)
fracflow_test(test_neighbor_list SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_neighbor_list.cpp LIBS fracflow_dem)
fracflow_test(test_dem_system SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_dem_system.cpp LIBS fracflow_dem)
fracflow_test(test_dem_no_allocation SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_no_allocation.cpp LIBS fracflow_dem)
fracflow_test(test_dem_stages SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_dem_stages.cpp LIBS fracflow_dem)
fracflow_test(test_law_registry SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_law_registry.cpp LIBS fracflow_dem fracflow_io)
