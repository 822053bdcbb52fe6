// The one reader of XML parameter files (scene, solver and study files) bounds what it hands to
// Teuchos: size, nesting depth and name length, checked without recursion, each an InputError
// (exit 2) naming the file and the limit. 10 000 nested lists used to overflow Teuchos' stack.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <vector>

#include "viscompm/core/error.hpp"
#include "viscompm/linalg/linear_solver.hpp"
#include "viscompm/params/parameter_io.hpp"
#include "viscompm/scene/scene.hpp"
#include "viscompm/study/solver_study.hpp"

using namespace viscompm;
using params::XmlLimits;

namespace {
const std::string inputs = VISCOMPM_SOURCE_DIR "/inputs";

std::string write_file(const std::string& name, const std::string& text) {
  const std::string file =
      std::filesystem::temp_directory_path() / ("viscompm_xml_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(file, std::ios::binary) << text;
  return file;
}

// `depth` ParameterLists, one inside the other, the innermost holding one parameter.
std::string nested(int depth) {
  std::string text;
  for (int i = 0; i < depth; ++i) text += "<ParameterList name=\"l" + std::to_string(i) + "\">\n";
  text += "<Parameter name=\"x\" type=\"double\" value=\"1\"/>\n";
  for (int i = 0; i < depth; ++i) text += "</ParameterList>\n";
  return text;
}

// The message of the InputError that `read` throws, or "" (the test then fails).
template <class F>
std::string input_error(F&& read) {
  try {
    read();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(XmlLimits, ShippedFilesAreWellInside) {
  int files = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(inputs)) {
    if (entry.path().extension() != ".xml") continue;
    std::ifstream in(entry.path());
    std::stringstream s;
    s << in.rdbuf();
    EXPECT_NO_THROW(params::check_xml_limits(s.str(), entry.path().string()));
    EXPECT_LT(s.str().size(), XmlLimits::max_bytes / 100) << entry.path();
    ++files;
  }
  EXPECT_GT(files, 20);
}

TEST(XmlLimits, TenThousandNestedListsAreBadInputNotACrash) {
  const std::string file = write_file("deep.xml", nested(10000));
  const std::string message = input_error([&] { params::read_xml_file(file); });
  EXPECT_NE(message.find(file), std::string::npos) << message;
  EXPECT_NE(message.find("nested more than 32 levels"), std::string::npos) << message;
  EXPECT_NE(message.find("line 33:"), std::string::npos) << message;  // the first list too deep
  std::filesystem::remove(file);
}

TEST(XmlLimits, DepthBoundIsExact) {
  // The root and 31 lists inside it hold; one more does not.
  EXPECT_NO_THROW(params::check_xml_limits(nested(XmlLimits::max_depth), "ok.xml"));
  const std::string message = input_error([&] { params::check_xml_limits(nested(XmlLimits::max_depth + 1), "x.xml"); });
  EXPECT_EQ(message.rfind("x.xml: line 33: nested more than 32 levels", 0), 0u) << message;
  // Empty elements, comments, CDATA, declarations and closing tags do not count as levels.
  std::string flat = "<?xml version=\"1.0\"?>\n<!DOCTYPE x>\n<ParameterList name=\"root\">\n";
  for (int i = 0; i < 1000; ++i)
    flat += "<Parameter name=\"p" + std::to_string(i) + "\" type=\"string\" value=\"a>b\"/><!-- <ParameterList> -->"
            "<ParameterList name=\"q" + std::to_string(i) + "\"></ParameterList>";
  flat += "<![CDATA[<a><b><c>]]></ParameterList>\n";
  EXPECT_NO_THROW(params::check_xml_limits(flat, "flat.xml"));
}

TEST(XmlLimits, LongNamesAreBadInput) {
  const std::string longest(XmlLimits::max_name_length, 'n');
  EXPECT_NO_THROW(params::check_xml_limits("<ParameterList name=\"" + longest + "\"/>", "ok.xml"));
  const std::string message =
      input_error([&] { params::check_xml_limits("<ParameterList\nname=\"" + longest + "n\"/>", "x.xml"); });
  EXPECT_EQ(message, "x.xml: line 2: a name of 257 characters, more than the 256 an XML parameter file allows");
  EXPECT_NE(input_error([&] { params::check_xml_limits("<" + longest + "x/>", "x.xml"); }).find("an element name of 257"),
            std::string::npos);
  EXPECT_NE(input_error([&] { params::check_xml_limits("<a " + longest + "x=\"1\"/>", "x.xml"); })
                .find("an attribute name of 257"),
            std::string::npos);
  // A long value is no name.
  EXPECT_NO_THROW(params::check_xml_limits("<Parameter name=\"a\" value=\"" + std::string(100000, '1') + "\"/>", "ok.xml"));
}

TEST(XmlLimits, HugeFilesAreBadInput) {
  std::string text = "<ParameterList name=\"root\">\n<!--" + std::string(XmlLimits::max_bytes, ' ') + "-->\n</ParameterList>\n";
  const std::string file = write_file("huge.xml", text);
  EXPECT_EQ(input_error([&] { params::read_xml_file(file); }),
            file + ": larger than the 4 MiB an XML parameter file may have");
  std::filesystem::remove(file);
  // A directory is named as one.
  EXPECT_EQ(input_error([&] { params::read_xml_file(inputs); }), inputs + ": is a directory, not a file");
}

// Scene, solver and study files alike go through the one reader.
TEST(XmlLimits, EveryReaderAnswersADeepFile) {
  const std::string file = write_file("deep_reader.xml", nested(10000));
  for (const auto& [what, read] :
       std::vector<std::pair<std::string, std::function<void()>>>{
           {"scene", [&] { scene::read_scene(file, {}); }},
           {"solver", [&] { linalg::SolverConfiguration::read(file); }},
           {"study", [&] { study::read_study(file, {}); }}}) {
    const std::string message = input_error(read);
    EXPECT_NE(message.find(file + ": line 33: nested more than 32 levels"), std::string::npos) << what << ": " << message;
  }
  std::filesystem::remove(file);
}
