// Output paths and whole-or-nothing writes (cf/file_io.hpp, libcf/src/io/file_io.cpp): two
// names for one file, names as long as the file system takes, and a signal mid-write.

#include <cf/file_io.hpp>
#include <cf/types.hpp>

#include <catch2/catch.hpp>

#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {

// A fresh directory for one test case, removed at the end.
struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& name)
      : path(fs::temp_directory_path() /
             ("cf_file_io_" + name + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() { fs::remove_all(path); }
  std::string operator/(const std::string& name) const { return (path / name).string(); }
  // Files left in the directory whose name holds ".tmp-".
  int temporaries() const {
    int n = 0;
    for (const auto& e : fs::directory_iterator(path))
      n += e.path().filename().string().find(".tmp-") != std::string::npos;
    return n;
  }
};

}  // namespace

TEST_CASE("two names for one output file are refused, existing or not") {
  TempDir d("names");
  const std::string a = d / "o.csv";
  const std::string b = (d.path / "." / "o.csv").string();
  CHECK(cf::canonical_path(a) == cf::canonical_path(b));
  CHECK(cf::canonical_path(a) == cf::canonical_path((d.path / "x" / ".." / "o.csv").string()));
  CHECK_THROWS_WITH(
      cf::check_output_path(b, {}, "writing", {a}),
      Catch::EndsWith("': is also the output '" + a + "'; each output needs its own file"));
  CHECK_THROWS_WITH(cf::write_outputs({{a, "1"}, {b, "2"}}, {}, "writing"),
                    Catch::Contains("each output needs its own file"));
  CHECK_FALSE(fs::exists(a));
  CHECK_NOTHROW(cf::check_output_path(a, {}, "writing", {d / "p.csv"}));
}

TEST_CASE("an output name as long as the file system takes is written; a longer one refused") {
  TempDir d("long");
  const long name_max = ::pathconf(d.path.c_str(), _PC_NAME_MAX);
  REQUIRE(name_max > 20);
  const std::string longest = d / std::string(static_cast<std::size_t>(name_max), 'a');
  cf::write_outputs({{longest, "bytes"}}, {}, "writing");  // its temporary name is cut short
  CHECK(fs::file_size(longest) == 5);
  CHECK(d.temporaries() == 0);
  const std::string beyond = d / std::string(static_cast<std::size_t>(name_max) + 1, 'b');
  CHECK_THROWS_WITH(cf::check_output_path(beyond, {}, "writing graph"),
                    Catch::Contains("writing graph '" + beyond + "'"));
}

TEST_CASE("a signal that ends the process mid-write leaves no temporary file") {
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
    TempDir d("signal");
    const std::string target = d / "graph.json";
    const pid_t child = ::fork();
    REQUIRE(child >= 0);
    if (child == 0) {
      std::signal(sig, SIG_DFL);
      const cf::StreamedOutput out{target, [sig](const cf::ByteSink& sink) {
                                     sink("{\"half\":", 8);
                                     std::raise(sig);  // the default ends the process
                                   }};
      cf::write_streamed_outputs({out}, {}, "writing graph");
      ::_exit(0);
    }
    int status = 0;
    REQUIRE(::waitpid(child, &status, 0) == child);
    INFO("signal " << sig);
    CHECK(WIFSIGNALED(status));
    CHECK(WTERMSIG(status) == sig);
    CHECK(d.temporaries() == 0);
    CHECK_FALSE(fs::exists(target));
  }
}

TEST_CASE("a signal the program handles itself does not cut the write short") {
  TempDir d("handled");
  const std::string target = d / "graph.json";
  const pid_t child = ::fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    std::signal(SIGHUP, [](int) {});  // as cfgen's stop between tasks, or Python's handler
    const cf::StreamedOutput out{target, [](const cf::ByteSink& sink) {
                                   sink("{\"a\":", 5);
                                   std::raise(SIGHUP);
                                   sink("1}", 2);
                                 }};
    cf::write_streamed_outputs({out}, {}, "writing graph");
    ::_exit(0);
  }
  int status = 0;
  REQUIRE(::waitpid(child, &status, 0) == child);
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
  std::ifstream in(target);
  std::string text;
  std::getline(in, text);
  CHECK(text == "{\"a\":1}");
  CHECK(d.temporaries() == 0);
}
