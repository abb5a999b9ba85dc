#pragma once
// One exception type for bad input. Its message always names the file, the field
// (or line) and what was expected, so that an app can print it and exit non-zero.
#include <stdexcept>
#include <string>

namespace saresgs {

class InputError : public std::runtime_error {
 public:
  InputError(const std::string& file, const std::string& field, const std::string& what)
      : std::runtime_error(file + ": " + field + ": " + what), file_(file), field_(field) {}
  const std::string& file() const { return file_; }
  const std::string& field() const { return field_; }

 private:
  std::string file_;
  std::string field_;
};

}  // namespace saresgs
