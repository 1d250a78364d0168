// PDDL parser: text -> S-expression tree (iterative, depth-limited) -> lifted Domain/Problem.
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <map>
#include <set>
#include <unordered_map>
#include <unordered_set>

#include "tamp/symbolic_planner/pddl.h"

namespace tamp::symbolic_planner::pddl {
namespace {

constexpr int kMaxDepth = 200;

struct SExpr {
  bool is_list{false};
  std::string text;  // symbol (lower-case) when !is_list
  std::vector<SExpr> items;
  Loc loc;
};

/// Thrown inside the parser only; converted to an Error at the API boundary.
struct ParseFailure {
  Error error;
};

class Reader {
 public:
  Reader(std::string_view text, std::string file) : text_(text), file_(std::move(file)) {}

  [[noreturn]] void fail(Loc loc, const std::string& msg, ErrorCode code = ErrorCode::kParseError) const {
    throw ParseFailure{Error(code, msg, SourceLocation{file_, loc.line, loc.column, ""})};
  }
  const std::string& file() const { return file_; }

  /// Reads every top-level expression.
  std::vector<SExpr> readAll() {
    std::vector<SExpr> out;
    if (text_.substr(0, 3) == "\xEF\xBB\xBF") pos_ = 3;  // UTF-8 byte-order mark
    std::vector<SExpr> stack;  // open lists
    for (;;) {
      skipSpace();
      if (pos_ >= text_.size()) break;
      const char c = text_[pos_];
      const Loc loc{line_, col_};
      if (c == '(') {
        if (static_cast<int>(stack.size()) >= kMaxDepth) fail(loc, "nesting deeper than 200 levels");
        advance();
        SExpr e;
        e.is_list = true;
        e.loc = loc;
        stack.push_back(std::move(e));
      } else if (c == ')') {
        if (stack.empty()) fail(loc, "unbalanced ')': no matching '('");
        advance();
        SExpr done = std::move(stack.back());
        stack.pop_back();
        if (stack.empty()) {
          out.push_back(std::move(done));
        } else {
          stack.back().items.push_back(std::move(done));
        }
      } else {
        SExpr sym;
        sym.loc = loc;
        while (pos_ < text_.size()) {
          const char d = text_[pos_];
          if (d == '(' || d == ')' || d == ';' || std::isspace(static_cast<unsigned char>(d))) break;
          if (static_cast<unsigned char>(d) < 32 || static_cast<unsigned char>(d) > 126) {
            fail(Loc{line_, col_}, "unexpected character (byte " +
                                       std::to_string(static_cast<unsigned char>(d)) + ")");
          }
          sym.text.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(d))));
          advance();
        }
        if (stack.empty()) fail(loc, "expected '(', got '" + sym.text + "'");
        stack.back().items.push_back(std::move(sym));
      }
    }
    if (!stack.empty()) fail(stack.back().loc, "unbalanced '(': missing ')' before end of file");
    return out;
  }

 private:
  void advance() {
    if (text_[pos_] == '\n') {
      ++line_;
      col_ = 1;
    } else {
      ++col_;
    }
    ++pos_;
  }
  void skipSpace() {
    while (pos_ < text_.size()) {
      const char c = text_[pos_];
      if (c == ';') {
        while (pos_ < text_.size() && text_[pos_] != '\n') advance();
      } else if (std::isspace(static_cast<unsigned char>(c))) {
        advance();
      } else {
        break;
      }
    }
  }

  std::string_view text_;
  std::string file_;
  size_t pos_{0};
  int line_{1};
  int col_{1};
};

std::string describe(const SExpr& e) {
  if (!e.is_list) return "'" + e.text + "'";
  if (e.items.empty()) return "'()'";
  if (!e.items[0].is_list) return "'(" + e.items[0].text + " ...)'";
  return "a list";
}

bool isNumber(const std::string& s, double* out) {
  if (s.empty()) return false;
  const char* b = s.data();
  const char* e = s.data() + s.size();
  double v = 0;
  auto r = std::from_chars(b, e, v);
  if (r.ec != std::errc() || r.ptr != e || !std::isfinite(v)) return false;
  if (out) *out = v;
  return true;
}

/// A name: letters, digits and `- _ . / @ [ ]`, starting with a letter, a digit or '_', and not a
/// number (Fast Downward accepts names such as `1st`; FF's lexer also allows brackets).
bool isName(const std::string& s) {
  if (s.empty()) return false;
  const unsigned char c = static_cast<unsigned char>(s[0]);
  if (!std::isalnum(c) && c != '_') return false;
  if (std::isdigit(c) && isNumber(s, nullptr)) return false;
  return std::all_of(s.begin(), s.end(), [](char ch) {
    const unsigned char u = static_cast<unsigned char>(ch);
    return std::isalnum(u) || ch == '-' || ch == '_' || ch == '.' || ch == '/' || ch == '@' || ch == '[' ||
           ch == ']';
  });
}

/// Adds the types of `more` not yet in `into` (an object declared more than once has every type it
/// was declared with).
void mergeTypes(std::vector<std::string>& into, const std::vector<std::string>& more) {
  for (const auto& t : more) {
    if (std::find(into.begin(), into.end(), t) == into.end()) into.push_back(t);
  }
}

/// Shared machinery for the domain and problem interpreters.
class Interpreter {
 public:
  explicit Interpreter(Reader& r) : r_(r) {}

  void error(Loc loc, const std::string& msg) {
    errors_.push_back(Error(ErrorCode::kParseError, msg, SourceLocation{r_.file(), loc.line, loc.column, ""}));
  }
  [[noreturn]] void fail(Loc loc, const std::string& msg, ErrorCode code = ErrorCode::kParseError) {
    r_.fail(loc, msg, code);
  }
  Status status() const {
    if (errors_.empty()) return Status::Ok();
    if (errors_.size() == 1) return errors_[0];
    Error e = errors_[0];
    e.message += " (and " + std::to_string(errors_.size() - 1) + " more error(s)):\n" + joinErrors(errors_);
    return e;
  }

  const SExpr& expectList(const SExpr& e, const std::string& what) {
    if (!e.is_list) fail(e.loc, "expected " + what + ", got " + describe(e));
    return e;
  }
  const std::string& expectSymbol(const SExpr& e, const std::string& what) {
    if (e.is_list) fail(e.loc, "expected " + what + ", got " + describe(e));
    return e.text;
  }
  std::string expectName(const SExpr& e, const std::string& what) {
    const std::string& s = expectSymbol(e, what);
    if (!isName(s)) fail(e.loc, "expected " + what + ", got '" + s + "'");
    return s;
  }
  std::string expectVariable(const SExpr& e) {
    const std::string& s = expectSymbol(e, "a variable (?name)");
    if (s.size() < 2 || s[0] != '?' || !isName(s.substr(1))) fail(e.loc, "expected a variable (?name), got '" + s + "'");
    return s;
  }
  static bool isHead(const SExpr& e, std::string_view head) {
    return e.is_list && !e.items.empty() && !e.items[0].is_list && e.items[0].text == head;
  }

  /// A typed list `a b - t c - (either u v) d`. `variables` selects `?x` names or object names.
  std::vector<TypedName> typedList(const std::vector<SExpr>& items, size_t from, bool variables) {
    std::vector<TypedName> out;
    size_t pending = 0;
    for (size_t i = from; i < items.size(); ++i) {
      const SExpr& it = items[i];
      if (!it.is_list && it.text == "-") {
        if (i + 1 >= items.size()) fail(it.loc, "expected a type after '-'");
        std::vector<std::string> types = typeSpec(items[i + 1]);
        if (pending == 0) fail(it.loc, "'-' with no names before it");
        for (size_t k = out.size() - pending; k < out.size(); ++k) out[k].types = types;
        pending = 0;
        ++i;
        continue;
      }
      TypedName tn;
      tn.loc = it.loc;
      tn.name = variables ? expectVariable(it) : expectName(it, "a name");
      out.push_back(std::move(tn));
      ++pending;
    }
    for (size_t k = out.size() - pending; k < out.size(); ++k) out[k].types = {"object"};
    return out;
  }

  std::vector<std::string> typeSpec(const SExpr& e) {
    if (!e.is_list) return {expectName(e, "a type name")};
    if (!isHead(e, "either") || e.items.size() < 2) fail(e.loc, "expected a type name or (either t1 t2 ...), got " + describe(e));
    std::vector<std::string> out;
    for (size_t i = 1; i < e.items.size(); ++i) out.push_back(expectName(e.items[i], "a type name"));
    return out;
  }

 protected:
  Reader& r_;
  std::vector<Error> errors_;
};

// ------------------------------------------------------------------------------------------------
// Domain

class DomainInterpreter : public Interpreter {
 public:
  DomainInterpreter(Reader& r, Domain& d) : Interpreter(r), d_(d) {}

  void run(const std::vector<SExpr>& top) {
    if (top.empty()) fail(Loc{1, 1}, "expected (define (domain NAME) ...), got an empty file");
    if (top.size() > 1) fail(top[1].loc, "expected end of file after the domain definition, got " + describe(top[1]));
    const SExpr& def = top[0];
    if (!isHead(def, "define")) fail(def.loc, "expected (define (domain NAME) ...), got " + describe(def));
    if (def.items.size() < 2 || !isHead(def.items[1], "domain") || def.items[1].items.size() != 2) {
      fail(def.items.size() < 2 ? def.loc : def.items[1].loc, "expected (domain NAME) after 'define'");
    }
    d_.name = expectName(def.items[1].items[1], "a domain name");
    d_.types.push_back({"object", {}, Loc{}});
    std::vector<const SExpr*> actions;
    for (size_t i = 2; i < def.items.size(); ++i) {
      const SExpr& sec = expectList(def.items[i], "a domain section such as (:predicates ...)");
      if (sec.items.empty() || sec.items[0].is_list) fail(sec.loc, "expected a section keyword, got " + describe(sec));
      const std::string& kw = sec.items[0].text;
      if (kw == ":requirements") {
        requirements(sec);
      } else if (kw == ":types") {
        types(sec);
      } else if (kw == ":constants") {
        for (auto& c : typedList(sec.items, 1, false)) d_.constants.push_back(std::move(c));
      } else if (kw == ":predicates") {
        for (size_t k = 1; k < sec.items.size(); ++k) d_.predicates.push_back(predicateDecl(sec.items[k], "a predicate declaration (name ?x ...)"));
      } else if (kw == ":functions") {
        functions(sec);
      } else if (kw == ":action") {
        actions.push_back(&sec);
      } else if (kw == ":derived") {
        fail(sec.loc, "derived predicates (:derived) are not supported", ErrorCode::kUnsupported);
      } else if (kw == ":durative-action") {
        fail(sec.loc, "durative actions are not supported", ErrorCode::kUnsupported);
      } else if (kw == ":constraints") {
        fail(sec.loc, "domain :constraints are not supported", ErrorCode::kUnsupported);
      } else {
        fail(sec.items[0].loc, "unknown domain section '" + kw +
                                   "' (expected :requirements, :types, :constants, :predicates, :functions or :action)");
      }
    }
    checkTypes();
    checkDuplicates();
    for (const SExpr* a : actions) d_.actions.push_back(action(*a));
    std::set<std::string> names;
    for (const auto& a : d_.actions) {
      if (!names.insert(a.name).second) error(a.loc, "action '" + a.name + "' is defined twice");
    }
  }

 private:
  /// Any requirement is accepted and recorded: requirements are not enforced (IPC files
  /// understate and over-declare them); a construct outside the fragment is refused where it is
  /// used.
  void requirements(const SExpr& sec) {
    for (size_t k = 1; k < sec.items.size(); ++k) {
      const std::string& req = expectSymbol(sec.items[k], "a requirement such as :strips");
      if (req.size() < 2 || req[0] != ':') fail(sec.items[k].loc, "expected a requirement such as :strips, got '" + req + "'");
      d_.requirements.push_back(req);
    }
  }

  /// Collects every declaration `a b - p` / `a b - (either p q)` / `a b` (parent object); the
  /// hierarchy is built in checkTypes().
  void types(const SExpr& sec) {
    size_t pending = 0;
    const auto& it = sec.items;
    for (size_t i = 1; i < it.size(); ++i) {
      if (!it[i].is_list && it[i].text == "-") {
        if (i + 1 >= it.size()) fail(it[i].loc, "expected a parent type after '-'");
        if (pending == 0) fail(it[i].loc, "'-' with no type names before it");
        const std::vector<std::string> parents = typeSpec(it[i + 1]);
        for (size_t k = type_decls_.size() - pending; k < type_decls_.size(); ++k) {
          type_decls_[k].parents = parents;
          type_decls_[k].parent_loc = it[i + 1].loc;
        }
        pending = 0;
        ++i;
        continue;
      }
      const std::string name = expectName(it[i], "a type name");
      type_decls_.push_back({name, {"object"}, it[i].loc, it[i].loc});
      ++pending;
    }
  }

  /// Builds the type DAG: the union of every declaration of a type (see TypeDecl), parents used
  /// but never declared become children of "object" (FF and Fast Downward do the same), cycles
  /// are errors. "object" may be re-declared (sometimes as "object - object"); it has no parent.
  void checkTypes() {
    std::map<std::string, size_t> index;  // name -> position in d_.types
    index["object"] = 0;
    auto declare = [&](const std::string& name, Loc loc) -> TypeDecl& {
      auto [it, inserted] = index.emplace(name, d_.types.size());
      if (inserted) d_.types.push_back({name, {}, loc});
      return d_.types[it->second];
    };
    for (const auto& td : type_decls_) {
      if (td.name == "object") continue;
      TypeDecl& t = declare(td.name, td.loc);
      for (const auto& p : td.parents) {
        if (p == td.name) {
          error(td.parent_loc, "type '" + td.name + "' is declared as its own parent");
          continue;
        }
        t.parents.push_back(p);
      }
    }
    for (const auto& td : type_decls_) {
      for (const auto& p : td.parents) {
        if (!index.count(p)) declare(p, td.parent_loc).parents.push_back("object");
      }
    }
    for (auto& t : d_.types) {
      std::sort(t.parents.begin(), t.parents.end());
      t.parents.erase(std::unique(t.parents.begin(), t.parents.end()), t.parents.end());
      if (t.parents.size() > 1) {
        t.parents.erase(std::remove(t.parents.begin(), t.parents.end(), std::string("object")), t.parents.end());
      }
      if (t.name != "object" && t.parents.empty()) t.parents.push_back("object");
    }
    if (!errors_.empty()) return;
    // Cycle check: depth-first search over the parent edges (0 = new, 1 = on the stack, 2 = done).
    std::vector<int> color(d_.types.size(), 0);
    for (size_t root = 0; root < d_.types.size(); ++root) {
      if (color[root]) continue;
      std::vector<std::pair<size_t, size_t>> stack{{root, 0}};  // type, next parent
      color[root] = 1;
      while (!stack.empty()) {
        auto& [t, next] = stack.back();
        if (next == d_.types[t].parents.size()) {
          color[t] = 2;
          stack.pop_back();
          continue;
        }
        const size_t p = index.at(d_.types[t].parents[next++]);
        if (color[p] == 1) {
          error(d_.types[p].loc, "type '" + d_.types[p].name + "' is part of a cycle in the type hierarchy (" +
                                     d_.types[t].name + " - " + d_.types[p].name + ")");
          return;
        }
        if (color[p] == 0) {
          color[p] = 1;
          stack.push_back({p, 0});
        }
      }
    }
  }

  void checkTypeNames(const std::vector<TypedName>& names) {
    for (const auto& n : names) {
      for (const auto& t : n.types) {
        if (!d_.findType(t)) error(n.loc, "unknown type '" + t + "' for '" + n.name + "'");
      }
    }
  }

  void checkDuplicates() {
    checkTypeNames(d_.constants);
    // A constant declared twice has the union of its types (as an object declared twice).
    std::vector<TypedName> merged;
    std::map<std::string, size_t> at;
    for (auto& c : d_.constants) {
      auto [it, inserted] = at.emplace(c.name, merged.size());
      if (inserted) {
        merged.push_back(std::move(c));
      } else {
        mergeTypes(merged[it->second].types, c.types);
      }
      constants_.insert(it->first);
    }
    d_.constants = std::move(merged);
    std::set<std::string> preds;
    for (const auto& p : d_.predicates) {
      if (!preds.insert(p.name).second) error(p.loc, "predicate '" + p.name + "' is declared twice");
      checkTypeNames(p.params);
    }
  }

  PredicateDecl predicateDecl(const SExpr& e, const std::string& what) {
    const SExpr& l = expectList(e, what);
    if (l.items.empty()) fail(l.loc, "expected " + what + ", got '()'");
    PredicateDecl p;
    p.loc = l.loc;
    p.name = expectName(l.items[0], "a predicate name");
    if (p.name == "=") fail(l.loc, "'=' is built in and cannot be declared");
    p.params = typedList(l.items, 1, true);
    return p;
  }

  void functions(const SExpr& sec) {
    const auto& it = sec.items;
    for (size_t i = 1; i < it.size(); ++i) {
      if (!it[i].is_list && it[i].text == "-") {
        if (i + 1 >= it.size()) fail(it[i].loc, "expected a function type after '-'");
        const std::string& t = expectSymbol(it[i + 1], "'number'");
        if (t != "number") fail(it[i + 1].loc, "only numeric functions are supported, got type '" + t + "'", ErrorCode::kUnsupported);
        ++i;
        continue;
      }
      d_.functions.push_back(predicateDecl(it[i], "a function declaration (name ?x ...)"));
    }
  }

  // --- actions ---------------------------------------------------------------------------------

  using Scope = std::vector<TypedName>;  // variables in scope (innermost last)

  const TypedName* lookupVar(const Scope& scope, const std::string& v) {
    for (auto it = scope.rbegin(); it != scope.rend(); ++it) {
      if (it->name == v) return &*it;
    }
    return nullptr;
  }

  Term term(const SExpr& e, const Scope& scope) {
    const std::string& s = expectSymbol(e, "a variable or constant");
    if (!s.empty() && s[0] == '?') {
      expectVariable(e);
      if (!lookupVar(scope, s)) error(e.loc, "variable '" + s + "' is not bound here");
    } else {
      if (!isName(s)) fail(e.loc, "expected a variable or constant, got '" + s + "'");
      if (!constants_.count(s)) error(e.loc, "'" + s + "' is not a declared constant (objects of the problem cannot appear in the domain)");
    }
    return Term{s};
  }

  Atom atom(const SExpr& e, const Scope& scope, bool function) {
    Atom a;
    a.loc = e.loc;
    a.predicate = expectName(e.items[0], function ? "a function name" : "a predicate name");
    const PredicateDecl* decl = function ? d_.findFunction(a.predicate) : d_.findPredicate(a.predicate);
    for (size_t i = 1; i < e.items.size(); ++i) a.args.push_back(term(e.items[i], scope));
    if (!decl) {
      error(e.loc, std::string(function ? "function" : "predicate") + " '" + a.predicate + "' is not declared");
    } else if (decl->params.size() != a.args.size()) {
      error(e.loc, "'" + a.predicate + "' takes " + std::to_string(decl->params.size()) + " argument(s), got " +
                       std::to_string(a.args.size()));
    }
    return a;
  }

  Formula formula(const SExpr& e, Scope& scope, int depth = 0) {
    if (depth > kMaxDepth) fail(e.loc, "formula nested too deeply");
    const SExpr& l = expectList(e, "a formula such as (and ...) or (p ?x)");
    Formula f;
    f.loc = l.loc;
    if (l.items.empty()) {  // "()" is the empty conjunction in some IPC files
      f.kind = FormulaKind::kAnd;
      return f;
    }
    const std::string& head = expectSymbol(l.items[0], "a predicate name or connective");
    auto arity = [&](size_t n) {
      if (l.items.size() != n + 1) fail(l.loc, "'" + head + "' takes " + std::to_string(n) + " argument(s), got " + std::to_string(l.items.size() - 1));
    };
    if (head == "and" || head == "or") {
      f.kind = head == "and" ? FormulaKind::kAnd : FormulaKind::kOr;
      for (size_t i = 1; i < l.items.size(); ++i) f.children.push_back(formula(l.items[i], scope, depth + 1));
    } else if (head == "not") {
      arity(1);
      f.kind = FormulaKind::kNot;
      f.children.push_back(formula(l.items[1], scope, depth + 1));
    } else if (head == "imply") {
      arity(2);
      f.kind = FormulaKind::kImply;
      f.children.push_back(formula(l.items[1], scope, depth + 1));
      f.children.push_back(formula(l.items[2], scope, depth + 1));
    } else if (head == "exists" || head == "forall") {
      arity(2);
      f.kind = head == "exists" ? FormulaKind::kExists : FormulaKind::kForall;
      const SExpr& vl = expectList(l.items[1], "a variable list (?x - type ...)");
      f.vars = typedList(vl.items, 0, true);
      checkTypeNames(f.vars);
      for (const auto& v : f.vars) scope.push_back(v);
      f.children.push_back(formula(l.items[2], scope, depth + 1));
      scope.resize(scope.size() - f.vars.size());
    } else if (head == "=") {
      arity(2);
      f.kind = FormulaKind::kEquals;
      f.atom.predicate = "=";
      f.atom.loc = l.loc;
      f.atom.args.push_back(term(l.items[1], scope));
      f.atom.args.push_back(term(l.items[2], scope));
    } else if (head == "<" || head == ">" || head == "<=" || head == ">=") {
      fail(l.loc, "numeric conditions ('" + head + "') are not supported", ErrorCode::kUnsupported);
    } else {
      f.kind = FormulaKind::kAtom;
      f.atom = atom(l, scope, false);
    }
    return f;
  }

  void effect(const SExpr& e, Scope& scope, std::vector<TypedName>& forall, std::vector<Formula>& conds,
              Action& act, int depth) {
    if (depth > kMaxDepth) fail(e.loc, "effect nested too deeply");
    const SExpr& l = expectList(e, "an effect such as (and ...), (p ?x) or (not (p ?x))");
    if (l.items.empty()) return;  // "()" = no effect
    const std::string& head = expectSymbol(l.items[0], "a predicate name or effect keyword");
    if (head == "and") {
      for (size_t i = 1; i < l.items.size(); ++i) effect(l.items[i], scope, forall, conds, act, depth + 1);
    } else if (head == "forall") {
      if (l.items.size() != 3) fail(l.loc, "expected (forall (?x - t ...) effect)");
      const SExpr& vl = expectList(l.items[1], "a variable list (?x - type ...)");
      std::vector<TypedName> vars = typedList(vl.items, 0, true);
      checkTypeNames(vars);
      for (const auto& v : vars) {
        scope.push_back(v);
        forall.push_back(v);
      }
      effect(l.items[2], scope, forall, conds, act, depth + 1);
      scope.resize(scope.size() - vars.size());
      forall.resize(forall.size() - vars.size());
    } else if (head == "when") {
      if (l.items.size() != 3) fail(l.loc, "expected (when condition effect)");
      conds.push_back(formula(l.items[1], scope, depth + 1));
      effect(l.items[2], scope, forall, conds, act, depth + 1);
      conds.pop_back();
    } else if (head == "increase") {
      if (l.items.size() != 3) fail(l.loc, "expected (increase (total-cost) amount)");
      if (!isHead(l.items[1], "total-cost") || l.items[1].items.size() != 1) {
        fail(l.items[1].loc, "only (increase (total-cost) ...) is supported (numeric fluents are not)", ErrorCode::kUnsupported);
      }
      if (!forall.empty() || !conds.empty()) {
        fail(l.loc, "(increase (total-cost) ...) inside forall/when is not supported", ErrorCode::kUnsupported);
      }
      CostExpr c;
      c.loc = l.items[2].loc;
      const SExpr& amount = l.items[2];
      if (!amount.is_list) {
        if (!isNumber(amount.text, &c.constant) || c.constant < 0) {
          fail(amount.loc, "expected a non-negative number or a function term as cost, got '" + amount.text + "'");
        }
      } else {
        if (amount.items.empty()) fail(amount.loc, "expected a function term such as (road-length ?a ?b)");
        c.is_function = true;
        c.function = atom(amount, scope, true);
        if (c.function.predicate == "total-cost") fail(amount.loc, "total-cost cannot be used as an action cost");
      }
      act.costs.push_back(std::move(c));
    } else if (head == "decrease" || head == "assign" || head == "scale-up" || head == "scale-down") {
      fail(l.loc, "numeric effect '" + head + "' is not supported (only (increase (total-cost) ...))", ErrorCode::kUnsupported);
    } else {
      EffectLiteral lit;
      lit.forall = forall;
      if (conds.empty()) {
        lit.condition = Formula::makeTrue();
      } else if (conds.size() == 1) {
        lit.condition = conds[0];
      } else {
        lit.condition.kind = FormulaKind::kAnd;
        lit.condition.children = conds;
      }
      const SExpr* a = &l;
      if (head == "not") {
        if (l.items.size() != 2) fail(l.loc, "expected (not (p ...))");
        a = &expectList(l.items[1], "an atom (p ...)");
        if (a->items.empty()) fail(a->loc, "expected an atom (p ...), got '()'");
        lit.negated = true;
      }
      const std::string& pname = expectSymbol(a->items[0], "a predicate name");
      if (pname == "=") fail(a->loc, "equality cannot be an effect");
      lit.atom = atom(*a, scope, false);
      act.effects.push_back(std::move(lit));
    }
  }

  Action action(const SExpr& sec) {
    Action a;
    a.loc = sec.loc;
    if (sec.items.size() < 2) fail(sec.loc, "expected an action name after :action");
    a.name = expectName(sec.items[1], "an action name");
    a.precondition = Formula::makeTrue();
    Scope scope;
    bool have_params = false, have_pre = false, have_eff = false;
    for (size_t i = 2; i < sec.items.size(); i += 2) {
      const std::string& kw = expectSymbol(sec.items[i], "':parameters', ':precondition' or ':effect'");
      if (i + 1 >= sec.items.size()) fail(sec.items[i].loc, "expected a value after '" + kw + "'");
      const SExpr& val = sec.items[i + 1];
      if (kw == ":parameters") {
        if (have_params || have_pre || have_eff) fail(sec.items[i].loc, ":parameters must come first and only once");
        have_params = true;
        a.parameters = typedList(expectList(val, "a parameter list (?x - type ...)").items, 0, true);
        checkTypeNames(a.parameters);
        std::set<std::string> seen;
        for (const auto& p : a.parameters) {
          if (!seen.insert(p.name).second) error(p.loc, "parameter '" + p.name + "' of action '" + a.name + "' appears twice");
        }
        scope = a.parameters;
      } else if (kw == ":precondition") {
        if (have_pre) fail(sec.items[i].loc, "two :precondition sections");
        have_pre = true;
        a.precondition = formula(val, scope);
      } else if (kw == ":effect") {
        if (have_eff) fail(sec.items[i].loc, "two :effect sections");
        have_eff = true;
        std::vector<TypedName> forall;
        std::vector<Formula> conds;
        effect(val, scope, forall, conds, a, 0);
      } else {
        fail(sec.items[i].loc, "expected ':parameters', ':precondition' or ':effect', got '" + kw + "'");
      }
    }
    return a;
  }

  struct TypeDeclaration {
    std::string name;
    std::vector<std::string> parents;
    Loc loc, parent_loc;
  };

  Domain& d_;
  std::set<std::string> constants_;
  std::vector<TypeDeclaration> type_decls_;  // every declaration, in file order
};

// ------------------------------------------------------------------------------------------------
// Problem

class ProblemInterpreter : public Interpreter {
 public:
  ProblemInterpreter(Reader& r, const Domain& d, Problem& p) : Interpreter(r), d_(d), p_(p) {
    for (const auto& c : d_.constants) objects_[c.name] = c.types;
  }

  void run(const std::vector<SExpr>& top) {
    if (top.empty()) fail(Loc{1, 1}, "expected (define (problem NAME) ...), got an empty file");
    if (top.size() > 1) fail(top[1].loc, "expected end of file after the problem definition, got " + describe(top[1]));
    const SExpr& def = top[0];
    if (!isHead(def, "define")) fail(def.loc, "expected (define (problem NAME) ...), got " + describe(def));
    if (def.items.size() < 2 || !isHead(def.items[1], "problem") || def.items[1].items.size() != 2) {
      fail(def.items.size() < 2 ? def.loc : def.items[1].loc, "expected (problem NAME) after 'define'");
    }
    p_.name = expectName(def.items[1].items[1], "a problem name");
    bool have_goal = false;
    std::vector<const SExpr*> inits;
    const SExpr* goal = nullptr;
    for (size_t i = 2; i < def.items.size(); ++i) {
      const SExpr& sec = expectList(def.items[i], "a problem section such as (:init ...)");
      if (sec.items.empty() || sec.items[0].is_list) fail(sec.loc, "expected a section keyword, got " + describe(sec));
      const std::string& kw = sec.items[0].text;
      if (kw == ":domain") {
        if (sec.items.size() != 2) fail(sec.loc, "expected (:domain NAME)");
        p_.domain_name = expectName(sec.items[1], "a domain name");
        if (p_.domain_name != d_.name) {
          error(sec.items[1].loc, "problem is for domain '" + p_.domain_name + "', but the domain is '" + d_.name + "'");
        }
      } else if (kw == ":requirements") {
        for (size_t k = 1; k < sec.items.size(); ++k) expectSymbol(sec.items[k], "a requirement");
      } else if (kw == ":objects") {
        std::vector<TypedName> objs = typedList(sec.items, 1, false);
        for (auto& o : objs) {
          for (const auto& t : o.types) {
            if (!d_.findType(t)) error(o.loc, "unknown type '" + t + "' for object '" + o.name + "'");
          }
          auto [it, inserted] = objects_.emplace(o.name, o.types);
          if (!inserted) {
            // Declared before: a domain constant repeated in :objects (pathways) or an object
            // listed twice. It has the union of its types; a constant re-declared with a new
            // type becomes a problem object entry with all of them.
            mergeTypes(it->second, o.types);
            auto po = std::find_if(p_.objects.begin(), p_.objects.end(), [&](const TypedName& x) { return x.name == o.name; });
            if (po != p_.objects.end()) {
              po->types = it->second;
            } else if (const auto c = std::find_if(d_.constants.begin(), d_.constants.end(),
                                                   [&](const TypedName& x) { return x.name == o.name; });
                       c != d_.constants.end() && c->types != it->second) {
              o.types = it->second;
              p_.objects.push_back(std::move(o));
            }
            continue;
          }
          p_.objects.push_back(std::move(o));
        }
      } else if (kw == ":init") {
        inits.push_back(&sec);
      } else if (kw == ":goal") {
        if (have_goal) fail(sec.loc, "two :goal sections");
        if (sec.items.size() != 2) fail(sec.loc, "expected (:goal FORMULA)");
        have_goal = true;
        goal = &sec.items[1];
      } else if (kw == ":metric") {
        metric(sec);
      } else if (kw == ":constraints") {
        fail(sec.loc, "problem :constraints are not supported", ErrorCode::kUnsupported);
      } else {
        fail(sec.items[0].loc, "unknown problem section '" + kw + "' (expected :domain, :objects, :init, :goal or :metric)");
      }
    }
    if (p_.domain_name.empty()) error(def.loc, "missing (:domain NAME)");
    section_ = ":init";
    for (const SExpr* s : inits) init(*s);
    section_ = ":goal";
    if (!goal) {
      error(def.loc, "missing (:goal ...)");
    } else {
      std::vector<TypedName> scope;
      p_.goal = groundFormula(*goal, scope, 0);
    }
  }

  Formula groundFormula(const SExpr& e, std::vector<TypedName>& scope, int depth) {
    if (depth > kMaxDepth) fail(e.loc, "formula nested too deeply");
    const SExpr& l = expectList(e, "a formula such as (and ...) or (p a b)");
    Formula f;
    f.loc = l.loc;
    if (l.items.empty()) {
      f.kind = FormulaKind::kAnd;
      return f;
    }
    const std::string& head = expectSymbol(l.items[0], "a predicate name or connective");
    auto arity = [&](size_t n) {
      if (l.items.size() != n + 1) fail(l.loc, "'" + head + "' takes " + std::to_string(n) + " argument(s)");
    };
    if (head == "and" || head == "or") {
      f.kind = head == "and" ? FormulaKind::kAnd : FormulaKind::kOr;
      for (size_t i = 1; i < l.items.size(); ++i) f.children.push_back(groundFormula(l.items[i], scope, depth + 1));
    } else if (head == "not") {
      arity(1);
      f.kind = FormulaKind::kNot;
      f.children.push_back(groundFormula(l.items[1], scope, depth + 1));
    } else if (head == "imply") {
      arity(2);
      f.kind = FormulaKind::kImply;
      f.children.push_back(groundFormula(l.items[1], scope, depth + 1));
      f.children.push_back(groundFormula(l.items[2], scope, depth + 1));
    } else if (head == "exists" || head == "forall") {
      arity(2);
      f.kind = head == "exists" ? FormulaKind::kExists : FormulaKind::kForall;
      f.vars = typedList(expectList(l.items[1], "a variable list").items, 0, true);
      for (const auto& v : f.vars) {
        for (const auto& t : v.types) {
          if (!d_.findType(t)) error(v.loc, "unknown type '" + t + "'");
        }
        scope.push_back(v);
      }
      f.children.push_back(groundFormula(l.items[2], scope, depth + 1));
      scope.resize(scope.size() - f.vars.size());
    } else if (head == "=") {
      arity(2);
      f.kind = FormulaKind::kEquals;
      f.atom.predicate = "=";
      f.atom.loc = l.loc;
      f.atom.args = {objectTerm(l.items[1], &scope), objectTerm(l.items[2], &scope)};
    } else if (head == "preference") {
      fail(l.loc, "preferences are not supported", ErrorCode::kUnsupported);
    } else if (head == "<" || head == ">" || head == "<=" || head == ">=") {
      fail(l.loc, "numeric conditions ('" + head + "') are not supported", ErrorCode::kUnsupported);
    } else {
      f.kind = FormulaKind::kAtom;
      f.atom = groundAtom(l, &scope);
    }
    return f;
  }

  Atom groundAtom(const SExpr& l, std::vector<TypedName>* scope, bool function = false) {
    expectList(l, function ? "a function term (f a b)" : "an atom (p a b)");
    if (l.items.empty()) fail(l.loc, "expected an atom (p a b), got '()'");
    Atom a;
    a.loc = l.loc;
    a.predicate = expectName(l.items[0], function ? "a function name" : "a predicate name");
    for (size_t i = 1; i < l.items.size(); ++i) a.args.push_back(objectTerm(l.items[i], scope));
    const PredicateDecl* decl = function ? d_.findFunction(a.predicate) : d_.findPredicate(a.predicate);
    if (!decl) {
      error(l.loc, std::string(function ? "function" : "predicate") + " '" + a.predicate + "' is not declared in the domain");
    } else if (decl->params.size() != a.args.size()) {
      error(l.loc, "'" + a.predicate + "' takes " + std::to_string(decl->params.size()) + " argument(s), got " +
                       std::to_string(a.args.size()));
    } else {
      checkArgumentTypes(l, a, *decl);
    }
    return a;
  }

  /// A ground argument must have a type the parameter accepts (one of its types, or a subtype of
  /// one): `(at can1 kitchen)` with `can1 - item` where `at` takes a location is an error, not a
  /// fact no action ever reads. Variables are left to their quantifier's type.
  void checkArgumentTypes(const SExpr& l, const Atom& a, const PredicateDecl& decl) {
    for (size_t i = 0; i < a.args.size(); ++i) {
      const std::string& name = a.args[i].name;
      if (name.empty() || name[0] == '?') continue;
      auto it = objects_.find(name);
      if (it == objects_.end()) continue;  // reported as unknown
      const std::vector<std::string>& want = decl.params[i].types;
      bool ok = false;
      for (const auto& have : it->second) {
        for (const auto& w : want) ok = ok || d_.isSubtype(have, w);
      }
      if (ok) continue;
      auto list = [](const std::vector<std::string>& v) {
        std::string out;
        for (const auto& t : v) out += (out.empty() ? "" : " or ") + t;
        return out;
      };
      error(l.items[i + 1].loc, "'" + name + "' (" + list(it->second) + ") cannot be argument " +
                                    std::to_string(i + 1) + " of '" + a.predicate + "', which takes " +
                                    list(want) + " (" + section_ + ")");
    }
  }

  Term objectTerm(const SExpr& e, std::vector<TypedName>* scope) {
    const std::string& s = expectSymbol(e, "an object name");
    if (!s.empty() && s[0] == '?') {
      bool bound = false;
      if (scope) {
        for (const auto& v : *scope) bound = bound || v.name == s;
      }
      if (!bound) error(e.loc, "variable '" + s + "' is not bound here");
      return Term{s};
    }
    if (!isName(s)) fail(e.loc, "expected an object name, got '" + s + "'");
    if (!objects_.count(s)) error(e.loc, "unknown object '" + s + "'");
    return Term{s};
  }

  void addObjects(const std::vector<TypedName>& objs) {
    for (const auto& o : objs) objects_.emplace(o.name, o.types);
  }

  void init(const SExpr& sec) {
    for (size_t k = 1; k < sec.items.size(); ++k) {
      const SExpr& l = expectList(sec.items[k], "an initial atom (p a b) or (= (f a) v)");
      if (l.items.empty()) fail(l.loc, "expected an initial atom, got '()'");
      if (isHead(l, "=")) {
        if (l.items.size() != 3 || !l.items[1].is_list) fail(l.loc, "expected (= (f a ...) NUMBER)");
        FunctionValue fv;
        fv.term = groundAtom(l.items[1], nullptr, true);
        const std::string& v = expectSymbol(l.items[2], "a number");
        if (!isNumber(v, &fv.value)) fail(l.items[2].loc, "expected a number, got '" + v + "'");
        p_.function_values.push_back(std::move(fv));
      } else if (isHead(l, "not")) {
        // Closed-world: (not p) in :init is redundant; accept and skip.
        continue;
      } else if (isHead(l, "at") && l.items.size() == 3 && !l.items[1].is_list && isNumber(l.items[1].text, nullptr)) {
        fail(l.loc, "timed initial literals are not supported", ErrorCode::kUnsupported);
      } else {
        p_.init.push_back(groundAtom(l, nullptr));
      }
    }
  }

  void metric(const SExpr& sec) {
    if (sec.items.size() != 3) fail(sec.loc, "expected (:metric minimize (total-cost))");
    const std::string& dir = expectSymbol(sec.items[1], "'minimize'");
    if (dir != "minimize") fail(sec.items[1].loc, "only 'minimize' metrics are supported, got '" + dir + "'", ErrorCode::kUnsupported);
    const SExpr& ex = sec.items[2];
    if (!(isHead(ex, "total-cost") && ex.items.size() == 1)) {
      fail(ex.loc, "only (:metric minimize (total-cost)) is supported", ErrorCode::kUnsupported);
    }
    p_.minimize_total_cost = true;
  }

 private:
  const Domain& d_;
  Problem& p_;
  std::unordered_map<std::string, std::vector<std::string>> objects_;

 public:
  const char* section_{"atom"};  ///< named in type errors (":init", ":goal", "goal", "init")
};

template <typename Fn>
auto guarded(Fn&& fn) -> decltype(fn()) {
  try {
    return fn();
  } catch (ParseFailure& f) {
    return std::move(f.error);
  } catch (const std::bad_alloc&) {
    return Error(ErrorCode::kInternal, "out of memory while parsing");
  }
}

void appendFormula(const Formula& f, std::string& out);

void appendTerms(const std::vector<Term>& args, std::string& out) {
  for (const auto& t : args) {
    out += ' ';
    out += t.name;
  }
}

void appendFormula(const Formula& f, std::string& out) {
  switch (f.kind) {
    case FormulaKind::kTrue: out += "(and)"; return;
    case FormulaKind::kFalse: out += "(or)"; return;
    case FormulaKind::kAtom: out += toString(f.atom); return;
    case FormulaKind::kEquals: out += "(="; appendTerms(f.atom.args, out); out += ')'; return;
    default: break;
  }
  static const char* names[] = {"", "", "", "", "not", "and", "or", "imply", "exists", "forall"};
  out += '(';
  out += names[static_cast<int>(f.kind)];
  if (f.kind == FormulaKind::kExists || f.kind == FormulaKind::kForall) {
    out += " (";
    for (size_t i = 0; i < f.vars.size(); ++i) {
      if (i) out += ' ';
      out += f.vars[i].name + " - " + (f.vars[i].types.empty() ? std::string("object") : f.vars[i].types[0]);
    }
    out += ')';
  }
  for (const auto& c : f.children) {
    out += ' ';
    appendFormula(c, out);
  }
  out += ')';
}

}  // namespace

const PredicateDecl* Domain::findPredicate(std::string_view n) const {
  for (const auto& p : predicates) {
    if (p.name == n) return &p;
  }
  return nullptr;
}
const PredicateDecl* Domain::findFunction(std::string_view n) const {
  for (const auto& p : functions) {
    if (p.name == n) return &p;
  }
  return nullptr;
}
const TypeDecl* Domain::findType(std::string_view n) const {
  for (const auto& t : types) {
    if (t.name == n) return &t;
  }
  return nullptr;
}
bool Domain::isSubtype(std::string_view type, std::string_view ancestor) const {
  if (type == ancestor) return true;
  if (ancestor == "object") return findType(type) != nullptr;
  // Depth-first over the parents; the hierarchy is acyclic (checked by the parser), and the
  // step bound keeps a hand-built cyclic Domain from looping.
  std::vector<std::string_view> stack{type};
  for (size_t steps = 0; !stack.empty() && steps <= types.size() * types.size() + 1; ++steps) {
    const std::string_view cur = stack.back();
    stack.pop_back();
    if (cur == ancestor) return true;
    const TypeDecl* t = findType(cur);
    if (!t) continue;
    for (const auto& p : t->parents) stack.push_back(p);
  }
  return false;
}

Result<Domain> parseDomain(std::string_view text, const std::string& file) {
  return guarded([&]() -> Result<Domain> {
    Reader r(text, file);
    std::vector<SExpr> top = r.readAll();
    Domain d;
    d.file = file;
    DomainInterpreter in(r, d);
    in.run(top);
    if (Status s = in.status(); !s.ok()) return s.error();
    return d;
  });
}

Result<Problem> parseProblem(std::string_view text, const Domain& domain, const std::string& file) {
  return guarded([&]() -> Result<Problem> {
    Reader r(text, file);
    std::vector<SExpr> top = r.readAll();
    Problem p;
    p.file = file;
    ProblemInterpreter in(r, domain, p);
    in.run(top);
    if (Status s = in.status(); !s.ok()) return s.error();
    return p;
  });
}

Result<Formula> parseGoalFormula(std::string_view text, const Domain& domain, const Problem& problem,
                                 const std::string& name) {
  return guarded([&]() -> Result<Formula> {
    Reader r(text, name);
    std::vector<SExpr> top = r.readAll();
    if (top.size() != 1) r.fail(Loc{1, 1}, "expected exactly one formula, got " + std::to_string(top.size()));
    Problem scratch;
    ProblemInterpreter in(r, domain, scratch);
    in.addObjects(problem.objects);
    in.section_ = "goal";
    std::vector<TypedName> scope;
    Formula f = in.groundFormula(top[0], scope, 0);
    if (Status s = in.status(); !s.ok()) return s.error();
    return f;
  });
}

Result<std::vector<Atom>> parseAtomList(std::string_view text, const Domain& domain,
                                        const Problem& problem, const std::string& name) {
  return guarded([&]() -> Result<std::vector<Atom>> {
    Reader r(text, name);
    std::vector<SExpr> top = r.readAll();
    Problem scratch;
    ProblemInterpreter in(r, domain, scratch);
    in.addObjects(problem.objects);
    in.section_ = "atom list";
    std::vector<Atom> out;
    for (const auto& e : top) out.push_back(in.groundAtom(e, nullptr));
    if (Status s = in.status(); !s.ok()) return s.error();
    return out;
  });
}

std::string toString(const Atom& a) {
  std::string out = "(" + a.predicate;
  appendTerms(a.args, out);
  out += ')';
  return out;
}

std::string toString(const Formula& f) {
  std::string out;
  appendFormula(f, out);
  return out;
}

}  // namespace tamp::symbolic_planner::pddl
