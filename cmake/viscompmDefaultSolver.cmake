# The scenes' default solver (a scene without a Solver section): the text of
# inputs/solvers/jacobi_cg.xml compiled into libviscompm, so that the default depends neither on
# where a scene lives nor on where the inputs are installed. CMake configures again when the file
# changes.
set(VISCOMPM_DEFAULT_SOLVER_FILE ${CMAKE_CURRENT_SOURCE_DIR}/inputs/solvers/jacobi_cg.xml)
file(READ ${VISCOMPM_DEFAULT_SOLVER_FILE} VISCOMPM_DEFAULT_SOLVER_XML)
configure_file(${CMAKE_CURRENT_LIST_DIR}/default_solver_xml.hpp.in ${CMAKE_BINARY_DIR}/generated/default_solver_xml.hpp
               @ONLY)
set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${VISCOMPM_DEFAULT_SOLVER_FILE})
target_include_directories(viscompm PRIVATE ${CMAKE_BINARY_DIR}/generated)
