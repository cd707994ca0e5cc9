// SPDX-License-Identifier: GPL-3.0-or-later
#pragma once
/// The problems of a TOML file as every reader reports them ("file:line:column: message"), apart
/// from base/TomlReader.h so that headers declaring a reader's error need not include toml++.
#include <stdexcept>
#include <string>
#include <vector>

namespace underfoot::base {

/// One problem in a TOML file.
struct TomlProblem {
    std::string file;
    int line = 0; ///< 0: the file as a whole (no position)
    int column = 0;
    std::string message;
    /// A consequence of an earlier problem (listed after the root causes).
    bool derived = false;
    /// "file:line:column: message" ("file: message" without a position).
    std::string toString() const;
};

/// Problems of a TOML file; what() lists them, one a line.
class TomlError : public std::runtime_error {
  public:
    explicit TomlError(std::vector<TomlProblem> problems);
    const std::vector<TomlProblem>& problems() const { return problems_; }

  private:
    std::vector<TomlProblem> problems_;
};

} // namespace underfoot::base
