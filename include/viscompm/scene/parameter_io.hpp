// Transitional: the parameter readers moved to params/parameter_io.hpp (the layer below scene/
// and linalg/). Only study/solver_study.cpp still includes this header; delete it once that file
// includes params/parameter_io.hpp.
#pragma once

#include "viscompm/params/parameter_io.hpp"

namespace viscompm::scene {
using params::parse_value;
using params::read_parameters;
using params::read_xml_file;
using params::set_entry;
}  // namespace viscompm::scene
