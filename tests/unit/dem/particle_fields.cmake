# Particle fields, global ids, reordering and external loads (src/dem/particle_store.hpp,
# src/dem/reorder_particles.*); included from tests/unit/dem/CMakeLists.txt.
fracflow_test(test_particle_fields SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_particle_fields.cpp LIBS fracflow_dem)
