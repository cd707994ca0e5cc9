// SPDX-License-Identifier: GPL-3.0-or-later
// The shared TOML reader itself (base/TomlReader.h): parseToml, then every typed accessor and
// the unknown-key check on every key of every table (depth-bounded walk), collecting and
// throwing; refusal: base::TomlError naming the source.
#include "FuzzSupport.h"
#include "base/TomlReader.h"

#include <string>
#include <vector>

namespace {
using underfoot::base::TomlReader;

enum class Colour { Red, Green };

void readEverything(TomlReader& r, const toml::table& t, const std::string& context, int depth) {
    if (depth > 8) return;
    r.checkKeys(t, {"id", "name", "seconds", "count", "enabled", "labels", "colour"}, context);
    for (auto&& [key, node] : t) {
        const std::string_view k = key.str();
        (void)r.number(t, k, context, -1e6, 1e6);
        (void)r.integer(t, k, context, false, -1000, 1000);
        (void)r.string(t, k, context, false);
        (void)r.id(t, k, context, false);
        (void)r.boolean(t, k, context);
        (void)r.strings(t, k, context);
        (void)r.choice<Colour>(t, k, context, {{"red", Colour::Red}, {"green", Colour::Green}});
        if (const toml::table* sub = r.table(t, k, context, false))
            readEverything(r, *sub, context + "." + std::string(k), depth + 1);
        if (const toml::array* array = r.array(t, k, context))
            for (const auto& element : *array)
                if (const toml::table* item = element.as_table())
                    readEverything(r, *item, context + "[]", depth + 1);
        (void)node;
    }
}
} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace underfoot;
    const std::string name = "fuzz_toml_reader.toml";
    fuzz::expectReadOrRefusal<base::TomlError>(name, [&] {
        const toml::table root = base::parseToml(fuzz::text(data, size), name);
        TomlReader collect(name);
        readEverything(collect, root, "the file", 0);
        for (const auto& p : collect.sortedProblems())
            if (p.file != name) fuzz::fail("a problem does not name the input: " + p.toString());
        TomlReader thrower(name, TomlReader::Mode::Throw);
        readEverything(thrower, root, "the file", 0);
    });
    return 0;
}
