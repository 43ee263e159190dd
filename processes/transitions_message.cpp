#include "processes/transitions_message.h"

#include "planner/common/format_error.h"
#include "processes/lcm_convert.h"

namespace acyclic::convert {

namespace {

std::string field(const std::string& base, std::size_t i) { return base + "[" + std::to_string(i) + "]"; }

}  // namespace

transitions_t toMessage(const std::vector<RememberedTransition>& transitions, const InterpolatorOptions& options,
                        const Scenario& sc) {
  transitions_t m{};
  m.options = outcomeOptionsText(options);
  for (const RememberedTransition& t : transitions) {
    const TransitionOutcome& o = t.outcome;
    transition_t mt{};
    mt.from = t.design.from;
    mt.to = t.design.to;
    mt.move = t.design.kind == TransitionDesign::Kind::Move;
    mt.repaired = o.repaired;
    mt.still = o.still;
    mt.how = o.how;
    mt.attempts = o.attempts;
    mt.refinements = o.refinements;
    mt.posture_calls = o.posture_calls;
    for (const MotionPiece& p : o.pieces) {
      transition_piece_t mp{};
      mp.stance = p.stance;
      for (const ContactSpec& c : p.contacts) mp.contacts.push_back(toMessage(c, sc));
      mp.num_contacts = static_cast<int32_t>(mp.contacts.size());
      for (const Configuration& q : p.knots) mp.knots.push_back(toMessageAsIs(q));
      mp.num_knots = static_cast<int32_t>(mp.knots.size());
      mt.pieces.push_back(std::move(mp));
    }
    mt.num_pieces = static_cast<int32_t>(mt.pieces.size());
    m.transitions.push_back(std::move(mt));
  }
  m.num_transitions = static_cast<int32_t>(m.transitions.size());
  return m;
}

std::size_t fillMemo(const transitions_t& m, const Plan& plan, const Scenario& sc, TransitionMemo& memo) {
  const std::string origin = "ACYCLIC_TRANSITIONS message (request " + std::to_string(m.request_id) + ")";
  const int n = static_cast<int>(plan.stances.size());
  std::vector<std::pair<std::string, TransitionOutcome>> read;
  for (std::size_t i = 0; i < m.transitions.size(); ++i) {
    const transition_t& mt = m.transitions[i];
    const std::string at = field("transitions", i);
    if (mt.from < 0 || mt.to <= mt.from || mt.to >= n)
      throw FormatError(origin, at + ".from", "two stances of the plan's " + std::to_string(n) + ", from before to");
    TransitionDesign d;
    d.kind = mt.move ? TransitionDesign::Kind::Move : TransitionDesign::Kind::Fixed;
    d.from = mt.from;
    d.to = mt.to;
    TransitionOutcome o;
    o.ok = true;
    o.repaired = mt.repaired;
    o.still = mt.still;
    o.how = mt.how;
    o.attempts = mt.attempts;
    o.refinements = mt.refinements;
    o.posture_calls = mt.posture_calls;
    for (std::size_t p = 0; p < mt.pieces.size(); ++p) {
      const transition_piece_t& mp = mt.pieces[p];
      const std::string pat = at + "." + field("pieces", p);
      MotionPiece piece;
      piece.stance = mp.stance;
      for (std::size_t k = 0; k < mp.contacts.size(); ++k)
        piece.contacts.push_back(fromMessage(mp.contacts[k], sc, origin, pat + "." + field("contacts", k)));
      for (std::size_t k = 0; k < mp.knots.size(); ++k)
        piece.knots.push_back(fromMessage(mp.knots[k], sc, origin + " " + pat + "." + field("knots", k)));
      o.pieces.push_back(std::move(piece));
    }
    read.emplace_back(transitionKey(plan, d), std::move(o));
  }
  // All or none: a message with one bad field is not half used.
  for (const auto& [key, o] : read) memo.store(key, o);
  return read.size();
}

std::vector<RememberedTransition> transitionsToSend(const plan_t& sent, const Scenario& sc, const TransitionMemo& memo) {
  return rememberedTransitions(fromMessage(sent, sc), memo);
}

}  // namespace acyclic::convert
