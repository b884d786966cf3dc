# Particle membrane unit tests (src/dem/membrane/particle_membrane.*); included from tests/unit/dem/CMakeLists.txt.
fracflow_test(test_particle_membrane SOURCES ${CMAKE_CURRENT_LIST_DIR}/test_particle_membrane.cpp LIBS fracflow_dem)
