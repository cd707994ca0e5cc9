// SPDX-License-Identifier: GPL-3.0-or-later
// [ordering] of a protocol file: repetitions, order, blocks, practice, breaks, Latin squares.
#include "experiment/ProtocolReader.h"

namespace underfoot::experiment::protocol_detail {

namespace {

/// Williams design: rows of a Latin square in which every condition follows every other equally
/// often (k rows for even k; k rows and their mirror images for odd k).
std::vector<std::vector<std::size_t>> williamsRows(std::size_t k) {
    std::vector<std::size_t> first;
    for (std::size_t i = 0, lo = 1, hi = k - 1; i < k; ++i) {
        if (i == 0)
            first.push_back(0);
        else if (i % 2 == 1)
            first.push_back(lo++);
        else
            first.push_back(hi--);
    }
    std::vector<std::vector<std::size_t>> rows;
    for (std::size_t r = 0; r < k; ++r) {
        std::vector<std::size_t> row;
        for (std::size_t c : first) row.push_back((c + r) % k);
        rows.push_back(row);
    }
    if (k % 2 == 1)
        for (std::size_t r = 0; r < k; ++r) rows.emplace_back(rows[r].rbegin(), rows[r].rend());
    return rows;
}

/// Replaces the implicit group "all" by one group per Williams row, each in a fixed order.
void applyLatinSquare(Protocol& p) {
    if (p.groups.size() != 1 || p.groups.front().stimuli.size() < 2) return;
    const std::vector<std::string> conditions = p.groups.front().stimuli;
    std::vector<Group> groups;
    const auto rows = williamsRows(conditions.size());
    for (std::size_t r = 0; r < rows.size(); ++r) {
        Group g;
        g.id = fmt::format("order{}", r + 1);
        for (std::size_t c : rows[r]) g.stimuli.push_back(conditions[c]);
        g.label = "order " + joinList(g.stimuli);
        groups.push_back(std::move(g));
    }
    p.groups = std::move(groups);
    p.ordering.order = OrderKind::Fixed;
}

} // namespace

/// Number of trials per group for the break check, and the feasibility of no-immediate-repeat.
void checkOrdering(Reader& r, const toml::table* orderingTable, const toml::table& root,
                   const Protocol& p) {
    const toml::source_region where = orderingTable ? orderingTable->source() : root.source();
    const auto& o = p.ordering;
    int largestTrials = 0;
    for (const auto& g : p.groups) {
        const int distinct = static_cast<int>(g.stimuli.size());
        const int blocks = o.blocks == BlockKind::Scale
                               ? std::max(1, static_cast<int>(p.questions.scales.size()))
                               : 1;
        const int trials = distinct * o.repetitions * blocks;
        largestTrials = std::max(largestTrials, trials);
        if (distinct == 0 || !o.noImmediateRepeat) continue;
        const std::string whose = p.design == DesignKind::Between ? fmt::format("group '{}'", g.id)
                                                                  : std::string("the protocol");
        if (o.order == OrderKind::Fixed) {
            // The declared order repeated: a repeat happens inside (duplicate neighbours) or
            // at the seam between repetitions.
            for (std::size_t i = 1; i < g.stimuli.size(); ++i)
                if (g.stimuli[i] == g.stimuli[i - 1])
                    r.problem(where, fmt::format("impossible ordering constraint: {} presents "
                                                 "'{}' twice in a row in its fixed order",
                                                 whose, g.stimuli[i]));
            if (o.repetitions > 1 && g.stimuli.front() == g.stimuli.back())
                r.problem(where,
                          fmt::format("impossible ordering constraint: with order = \"fixed\" "
                                      "and {} repetitions, {} repeats '{}' at the seam between "
                                      "repetitions",
                                      o.repetitions, whose, g.stimuli.front()));
        } else if (distinct < 2 && trials > 1) {
            r.problem(where,
                      fmt::format("impossible ordering constraint: no_immediate_repeat with {} "
                                  "repetitions of a single stimulus in {}; at least two "
                                  "different stimuli are needed",
                                  o.repetitions, whose));
        }
    }
    if (o.breakEvery > 0 && o.breakEvery >= largestTrials)
        r.problem(where, fmt::format("break_every = {} leaves no break: the longest plan has {} "
                                     "trials; expected a number below {}",
                                     o.breakEvery, largestTrials, largestTrials));
}

void readOrdering(ProtocolParse& x) {
    Reader& r = x.r;
    const toml::table& root = x.root;
    Protocol& p = x.p;
    // [ordering]
    x.orderingTable = r.table(root, "ordering", "the protocol file", false);
    if (x.orderingTable) {
        const toml::table& t = *x.orderingTable;
        const char* ctx = "[ordering]";
        r.checkKeys(t,
                    {"repetitions", "order", "blocks", "no_immediate_repeat", "practice",
                     "break_every", "counterbalance"},
                    ctx);
        p.ordering.repetitions =
            static_cast<int>(r.integer(t, "repetitions", ctx, false, 1, 1000).value_or(1));
        if (auto o = r.choice<OrderKind>(
                t, "order", ctx, {{"random", OrderKind::Random}, {"fixed", OrderKind::Fixed}}))
            p.ordering.order = *o;
        if (auto b = r.choice<BlockKind>(t, "blocks", ctx,
                                         {{"none", BlockKind::None},
                                          {"repetition", BlockKind::Repetition},
                                          {"scale", BlockKind::Scale}}))
            p.ordering.blocks = *b;
        if (auto c = r.choice<Counterbalance>(
                t, "counterbalance", ctx,
                {{"none", Counterbalance::None}, {"latin_square", Counterbalance::LatinSquare}})) {
            p.ordering.counterbalance = *c;
            if (*c == Counterbalance::LatinSquare) {
                if (p.design != DesignKind::Within)
                    r.problem(*t.get("counterbalance"),
                              "counterbalance = \"latin_square\" balances the order of "
                              "conditions within subjects; expected design type = \"within\"");
                else if (t.get("order") && p.ordering.order == OrderKind::Random)
                    r.problem(*t.get("order"),
                              "order = \"random\" contradicts counterbalance = "
                              "\"latin_square\" (each Latin-square row is a fixed order); "
                              "remove 'order'");
                else if (t.get("blocks") && p.ordering.blocks == BlockKind::Scale)
                    r.problem(*t.get("blocks"),
                              "blocks = \"scale\" cannot be combined with counterbalance = "
                              "\"latin_square\"");
                else
                    applyLatinSquare(p);
            }
        }
        p.ordering.noImmediateRepeat = r.boolean(t, "no_immediate_repeat", ctx).value_or(false);
        for (const auto& [sid, where] : r.strings(t, "practice", ctx)) {
            if (!p.stimulus(sid))
                r.problem(where, fmt::format("practice names unknown stimulus '{}'; expected one "
                                             "of the [[stimuli]] ids",
                                             sid));
            else
                p.ordering.practice.push_back(sid);
        }
        p.ordering.breakEvery =
            static_cast<int>(r.integer(t, "break_every", ctx, false, 0, 100000).value_or(0));
    }
}

} // namespace underfoot::experiment::protocol_detail
