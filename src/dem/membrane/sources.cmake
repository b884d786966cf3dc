target_sources(fracflow_dem PRIVATE ${CMAKE_CURRENT_LIST_DIR}/flexible_membrane.cpp ${CMAKE_CURRENT_LIST_DIR}/particle_membrane.cpp
  ${CMAKE_CURRENT_LIST_DIR}/membrane_boundary.cpp)
