# The dependencies of viscompm, found the same way by the project itself and by projects that
# use an installed viscompm (viscompmConfig.cmake includes this file). Where a dependency ships
# an imported target it is used (MPI::MPI_CXX, Eigen3::Eigen, hdf5::hdf5); Debian's Trilinos 13.2
# ships none, so its include directories and libraries are gathered into viscompm::trilinos.
# Only what a consumer needs: MPI's C++ interface (no C compiler is asked for).
find_package(MPI REQUIRED COMPONENTS CXX)
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
if(DEFINED VISCOMPM_HDF5_LIBRARIES)
  # An installed viscompm (viscompmConfig.cmake): the parallel HDF5 it was built with, as the
  # target its libraries name. FindHDF5 would need the consumer to enable the C language.
  if(NOT TARGET hdf5::hdf5)
    add_library(hdf5::hdf5 INTERFACE IMPORTED)
    set_target_properties(hdf5::hdf5 PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${VISCOMPM_HDF5_INCLUDE_DIRS}"
                                                INTERFACE_LINK_LIBRARIES "${VISCOMPM_HDF5_LIBRARIES}")
  endif()
else()
  set(HDF5_PREFER_PARALLEL TRUE)
  find_package(HDF5 REQUIRED COMPONENTS C)
  if(NOT HDF5_IS_PARALLEL)
    message(FATAL_ERROR "viscompm needs parallel HDF5 (Debian: libhdf5-openmpi-dev)")
  endif()
endif()
# Meshes (Assimp) and level sets (OpenVDB, which needs TBB and Boost.Iostreams): geometry/ only.
find_package(assimp REQUIRED)
list(APPEND CMAKE_MODULE_PATH /usr/lib/x86_64-linux-gnu/cmake/OpenVDB /usr/lib/cmake/OpenVDB /usr/local/lib/cmake/OpenVDB)
find_package(OpenVDB REQUIRED)
find_package(Trilinos REQUIRED COMPONENTS Teuchos Tpetra Belos Ifpack2 MueLu Xpetra Zoltan2 Galeri)

if(NOT TARGET viscompm::trilinos)
  add_library(viscompm::trilinos INTERFACE IMPORTED)
  # Trilinos' CMake files name the scotch/ptscotch libraries by absolute path (Debian:
  # libptscotch-dev libscotch-dev must be installed for the link to succeed).
  set_target_properties(viscompm::trilinos PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${Trilinos_INCLUDE_DIRS};${Trilinos_TPL_INCLUDE_DIRS}"
    INTERFACE_LINK_DIRECTORIES "${Trilinos_LIBRARY_DIRS}"
    INTERFACE_LINK_LIBRARIES "${Trilinos_LIBRARIES};${Trilinos_TPL_LIBRARIES};MPI::MPI_CXX")
endif()
