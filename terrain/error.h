// The one error type of Driftscape. Library code throws it with a message that
// names the input, the value and the fix; the command line prints
// "drift: error: <message>" and exits 1. Usage errors (bad flags) exit 2.
#pragma once

#include <stdexcept>
#include <string>

namespace drift {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
};

// Thrown when a progress callback asked to stop.
class Cancelled : public Error {
 public:
  Cancelled() : Error("cancelled") {}
};

}  // namespace drift
