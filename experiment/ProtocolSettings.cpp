// SPDX-License-Identifier: GPL-3.0-or-later
// The header and settings tables of a protocol file: [protocol], [design], [timing], [input],
// [laps], [clips], [[participant_fields]], [rules], [simulation].
#include "experiment/ProtocolReader.h"

namespace underfoot::experiment::protocol_detail {

void readHeader(ProtocolParse& x) {
    Reader& r = x.r;
    const toml::table& root = x.root;
    Protocol& p = x.p;
    const std::string& sourceName = p.sourceName;
    // [protocol]
    if (auto t = r.table(root, "protocol", "the protocol file", true)) {
        r.checkKeys(*t,
                    {"id", "version", "title", "participant_title", "reference", "briefing",
                     "notes", "description"},
                    "[protocol]");
        p.id = r.id(*t, "id", "[protocol]", true).value_or("");
        p.version =
            static_cast<int>(r.integer(*t, "version", "[protocol]", true, 1, 1000000).value_or(1));
        p.title = r.string(*t, "title", "[protocol]", true).value_or("");
        p.reference = r.string(*t, "reference", "[protocol]", false).value_or("");
        p.participantTitle = r.string(*t, "participant_title", "[protocol]", false).value_or("");
        p.briefing = r.string(*t, "briefing", "[protocol]", false).value_or("");
        p.notes = r.string(*t, "notes", "[protocol]", false).value_or("");
        if (auto d = r.string(*t, "description", "[protocol]", false)) {
            const toml::node& where = *t->get("description");
            if (t->get("notes"))
                r.problem(where, "[protocol] has both 'description' and 'notes'; 'description' "
                                 "is the older name of 'notes': keep one");
            else
                p.notes = *d;
            p.warnings.push_back(
                {sourceName, static_cast<int>(where.source().begin.line),
                 static_cast<int>(where.source().begin.column),
                 "'description' in [protocol] is read as 'notes' (the experimenter's notes, never "
                 "shown to participants); rename it to 'notes', and put what participants read "
                 "in 'briefing'"});
        }
    }

    // [design]
    if (auto t = r.table(root, "design", "the protocol file", true)) {
        r.checkKeys(*t, {"type"}, "[design]");
        if (auto d = r.choice<DesignKind>(
                *t, "type", "[design]",
                {{"within", DesignKind::Within}, {"between", DesignKind::Between}}))
            p.design = *d;
        else if (!t->get("type"))
            r.problem(*t, "missing key 'type' in [design]; expected \"within\" or \"between\"");
    }

    // [timing]
    if (auto t = r.table(root, "timing", "the protocol file", false)) {
        r.checkKeys(*t, {"briefing_s", "trial_s", "break_s"}, "[timing]");
        p.timing.briefingS = r.number(*t, "briefing_s", "[timing]", 0, 86400).value_or(120.0);
        p.timing.trialS = r.number(*t, "trial_s", "[timing]", 0, 86400).value_or(45.0);
        p.timing.breakS = r.number(*t, "break_s", "[timing]", 0, 86400).value_or(60.0);
    }

    // [input]: the default input of every stimulus.
    if (auto t = r.table(root, "input", "the protocol file", false))
        x.defaultInput = readInput(r, *t, "[input]", Input{});
}

void readSettings(ProtocolParse& x) {
    Reader& r = x.r;
    const toml::table& root = x.root;
    Protocol& p = x.p;
    // [laps]
    if (auto t = r.table(root, "laps", "the protocol file", false)) {
        r.checkKeys(*t, {"baseline", "feedback"}, "[laps]");
        p.laps.baseline =
            static_cast<int>(r.integer(*t, "baseline", "[laps]", false, 0, 100).value_or(0));
        p.laps.feedback =
            static_cast<int>(r.integer(*t, "feedback", "[laps]", true, 1, 100).value_or(1));
    }

    // [clips]
    if (auto t = r.table(root, "clips", "the protocol file", false)) {
        r.checkKeys(*t, {"seconds", "seed", "replay"}, "[clips]");
        p.clips.enabled = true;
        p.clips.seconds = r.number(*t, "seconds", "[clips]", 0.5, 600).value_or(10.0);
        p.clips.seed = static_cast<std::uint64_t>(
            r.integer(*t, "seed", "[clips]", false, 0, std::numeric_limits<std::int64_t>::max())
                .value_or(1));
        p.clips.replay = r.boolean(*t, "replay", "[clips]").value_or(true);
        if (p.laps.total() > 0)
            r.problem(*t, "[clips] (a listening test) and [laps] (an interactive test) exclude "
                          "each other; expected one of them");
    }
    // A lab-supplied clip makes the protocol a listening test even without a [clips] table.
    for (const auto& s : p.stimuli)
        if (s.clip) p.clips.enabled = true;
    if (p.clips.enabled && p.laps.total() > 0 && !root.get("clips"))
        r.problem(*root.get("laps"), "[laps] (an interactive test) cannot be combined with "
                                     "lab-supplied clips (a listening test)");

    // [[participant_fields]]
    if (const toml::node* node = root.get("participant_fields")) {
        if (!node->is_array_of_tables())
            r.problem(*node, "'participant_fields' must be an array of tables "
                             "([[participant_fields]])");
        else
            for (const toml::node& element : *node->as_array()) {
                const toml::table& t = *element.as_table();
                const std::string ctx =
                    fmt::format("[[participant_fields]] #{}", p.participantFields.size() + 1);
                r.checkKeys(t, {"id", "label", "options", "required"}, ctx);
                ParticipantField f;
                f.id = r.id(t, "id", ctx, true).value_or("");
                f.label = r.string(t, "label", ctx, false).value_or(f.id);
                f.required = r.boolean(t, "required", ctx).value_or(true);
                std::set<std::string> seen;
                for (const auto& [option, where] : r.strings(t, "options", ctx)) {
                    if (option.empty() || !seen.insert(option).second)
                        r.problem(where, fmt::format("option '{}' of {} is empty or listed twice",
                                                     option, ctx));
                    else
                        f.options.push_back(option);
                }
                if (t.get("options") && f.options.empty() && t.get("options")->is_array())
                    r.problem(*t.get("options"),
                              fmt::format("'options' of {} is empty; expected the allowed "
                                          "answers, or no 'options' for free text",
                                          ctx));
                static const std::set<std::string> kBuiltIn = {"code",  "age",     "gender",
                                                               "shoes", "hearing", "group"};
                if (kBuiltIn.count(f.id))
                    r.problem(t, fmt::format("participant field '{}' is built in; expected "
                                             "another id",
                                             f.id));
                else if (!f.id.empty() && p.participantField(f.id))
                    r.problem(t, fmt::format("participant field '{}' is declared twice", f.id));
                else if (!f.id.empty())
                    p.participantFields.push_back(std::move(f));
            }
    }

    // [rules]
    if (auto t = r.table(root, "rules", "the protocol file", false)) {
        r.checkKeys(*t, {"lock"}, "[rules]");
        if (auto l = r.choice<LockRule>(
                *t, "lock", "[rules]",
                {{"next_trial", LockRule::NextTrialStart}, {"answer", LockRule::OnAnswer}}))
            p.lock = *l;
    }

    // [simulation]: the published data synthetic participants answer from.
    if (auto t = r.table(root, "simulation", "the protocol file", false)) {
        r.checkKeys(*t, {"confusion", "rating_model"}, "[simulation]");
        auto relativePath = [&](const toml::node& node, const std::string& value) {
            if (value.empty() || value.front() == '/' || value.find("..") != std::string::npos)
                r.problem(node, fmt::format("'{}' in [simulation]: expected a path relative to "
                                            "the protocol's folder, without '..'",
                                            value));
        };
        if (const toml::node* c = t->get("confusion")) {
            if (c->is_string()) {
                p.simulation.confusion[""] = c->as_string()->get();
                relativePath(*c, c->as_string()->get());
            } else if (c->is_table()) {
                for (auto&& [key, node] : *c->as_table()) {
                    const std::string group(key.str());
                    if (!p.group(group))
                        r.problem(node, fmt::format("[simulation] confusion names group '{}', "
                                                    "which is not a group of the protocol",
                                                    group));
                    if (!node.is_string()) {
                        r.problem(node, fmt::format("confusion.{} in [simulation] must be a "
                                                    "string (a CSV file)",
                                                    group));
                        continue;
                    }
                    p.simulation.confusion[group] = node.as_string()->get();
                    relativePath(node, node.as_string()->get());
                }
            } else {
                r.problem(*c, "'confusion' in [simulation] must be a file name or a table of "
                              "group = file");
            }
        }
        if (auto m = r.string(*t, "rating_model", "[simulation]", false)) {
            relativePath(*t->get("rating_model"), *m);
            p.simulation.ratingModel = *m;
        }
    }
}

} // namespace underfoot::experiment::protocol_detail
