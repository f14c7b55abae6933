#include "lsystem/detail/expression_parser.h"

#include <algorithm>
#include <charconv>
#include <cmath>

namespace sprig::lsystem::detail {

namespace {

/// Thrown inside the expression parser once the error is reported; caught by compile().
struct ExprFail {};

struct FunctionInfo {
  const char* name;
  Op op;
  int arity;
};

constexpr FunctionInfo kFunctions[] = {
    {"sin", Op::Sin, 1},     {"cos", Op::Cos, 1},     {"tan", Op::Tan, 1},     {"asin", Op::Asin, 1},
    {"acos", Op::Acos, 1},   {"atan", Op::Atan, 1},   {"atan2", Op::Atan2, 2}, {"sqrt", Op::Sqrt, 1},
    {"exp", Op::Exp, 1},     {"log", Op::Log, 1},     {"pow", Op::PowFn, 2},   {"abs", Op::Abs, 1},
    {"min", Op::Min, 2},     {"max", Op::Max, 2},     {"floor", Op::Floor, 1}, {"ceil", Op::Ceil, 1},
    {"sign", Op::Sign, 1},   {"ran", Op::Ran, 1},     {"nran", Op::Nran, 2},   {"fabs", Op::Abs, 1},
    {"trunc", Op::Round, 1}, {"bran", Op::Bran, 2},   {"biran", Op::Biran, 2},
};

/// cpfg functions Sprig does not implement, with why.
struct UnsupportedFunction {
  const char* name;
  const char* what;
};
constexpr UnsupportedFunction kUnsupportedFunctions[] = {
    {"printf", "output; it is a statement of its own"}, {"fprintf", "file output"}, {"fopen", "file input and output"},
    {"fclose", "file input and output"}, {"fflush", "file input and output"}, {"fscanf", "file input"},

    {"play", "sound"}, {"inblob", "environment field"}, {"vvXmin", "view volume"}, {"vvXmax", "view volume"},
    {"vvYmin", "view volume"}, {"vvYmax", "view volume"}, {"vvZmin", "view volume"}, {"vvZmax", "view volume"},
    {"vvScale", "view volume"}, {"Display", "display"}, {"SetDerivationLength", "changes the derivation length"},
    {"GetDerivationLength", "derivation length"},
};

/// Nesting of unary operators and parentheses beyond which an expression is rejected.
constexpr int kMaxNesting = 48;

int arityOf(Op op) {
  switch (op) {
    case Op::Const: case Op::Var: return 0;
    case Op::Neg: case Op::Not: case Op::Sin: case Op::Cos: case Op::Tan: case Op::Asin: case Op::Acos:
    case Op::Atan: case Op::Sqrt: case Op::Exp: case Op::Log: case Op::Abs: case Op::Floor: case Op::Ceil:
    case Op::Sign: case Op::Ran: case Op::Round: case Op::Srand: case Op::Stop: case Op::Func: case Op::Curve:
    case Op::ArrayAt: case Op::ArrayLoad:
      return 1;
    case Op::CurveLength: return 0;
    case Op::Select: return 3;
    default: return 2;
  }
}

const std::vector<std::string> kNoVars;

}  // namespace

struct ExpressionParser::Node {
  Op op = Op::Const;
  double value = 0;
  uint16_t var = 0;
  int kids[3] = {-1, -1, -1};
  int col = 0;  ///< ArrayAt: the column of its `[`, for errors
};

struct ExpressionParser::Token {
  enum Kind { Num, Ident, Punct, End } kind = End;
  std::string_view text;
  double value = 0;
  int col = 0;  ///< 0-based
};

struct ExpressionParser::State {
  State(Span sp, const std::vector<std::string>& v) : span(sp), vars(&v), pos(sp.b) {}
  Span span;
  const std::vector<std::string>* vars = nullptr;
  std::vector<Node> nodes;
  Token tok;
  int pos = 0;
  int depth = 0;  ///< nesting of unary operators and parentheses
};

// ---- tokens ------------------------------------------------------------------------------

void ExpressionParser::lex(State& st) {
  const std::string& s = scanner_.line(st.span.line);
  int i = st.pos;
  // cpfg's expression lexer has no rule for '\': flex's default rule passes over it, so a
  // stray backslash (the one a '#define f(x) \\' line continuation leaves in the body) is
  // blank there.
  const bool cpfg = scanner_.dialect() == Dialect::Cpfg;
  while (i < st.span.e && (isSpace(s[i]) || (cpfg && s[i] == '\\'))) ++i;
  Token t;
  t.col = i;
  if (i >= st.span.e) {
    t.kind = Token::End;
    st.pos = i;
    st.tok = t;
    return;
  }
  char c = s[i];
  if (std::isdigit(static_cast<unsigned char>(c)) || (c == '.' && i + 1 < st.span.e && std::isdigit(static_cast<unsigned char>(s[i + 1])))) {
    int j = i;
    while (j < st.span.e && (std::isdigit(static_cast<unsigned char>(s[j])) || s[j] == '.')) ++j;
    if (j < st.span.e && (s[j] == 'e' || s[j] == 'E')) {
      int k = j + 1;
      if (k < st.span.e && (s[k] == '+' || s[k] == '-')) ++k;
      if (k < st.span.e && std::isdigit(static_cast<unsigned char>(s[k]))) {
        j = k;
        while (j < st.span.e && std::isdigit(static_cast<unsigned char>(s[j]))) ++j;
      }
    }
    double v = 0;
    auto r = std::from_chars(s.data() + i, s.data() + j, v);
    if (r.ec != std::errc() || r.ptr != s.data() + j) {
      scanner_.error(st.span.line, i, "malformed number '" + s.substr(i, j - i) + "'");
      throw ExprFail{};
    }
    t.kind = Token::Num;
    t.value = v;
    t.text = std::string_view(s).substr(i, j - i);
    st.pos = j;
  } else if (isIdentStart(c)) {
    int j = i;
    while (j < st.span.e && isIdentChar(s[j])) ++j;
    t.kind = Token::Ident;
    t.text = std::string_view(s).substr(i, j - i);
    st.pos = j;
  } else {
    static const char* two[] = {"<=", ">=", "==", "!=", "&&", "||", "<>"};
    int len = 0;
    for (const char* op : two)
      if (i + 1 < st.span.e && s.compare(i, 2, op) == 0) len = 2;
    if (!len) {
      const bool bracket = (c == '[' || c == ']') && tables_ && !tables_->arrays.empty();  // cpfg's arrays
      if (std::string_view("+-*/^<>!(),?:%").find(c) == std::string_view::npos && !bracket) {
        scanner_.error(st.span.line, i, std::string("unexpected character '") + c + "' in expression");
        throw ExprFail{};
      }
      len = 1;
    }
    t.kind = Token::Punct;
    t.text = std::string_view(s).substr(i, len);
    st.pos = i + len;
  }
  st.tok = t;
}

bool ExpressionParser::isPunct(const State& st, std::string_view p) const {
  return st.tok.kind == Token::Punct && st.tok.text == p;
}

int ExpressionParser::node(State& st, Op op, int a, int b, int c) {
  Node n;
  n.op = op;
  n.kids[0] = a;
  n.kids[1] = b;
  n.kids[2] = c;
  st.nodes.push_back(n);
  return static_cast<int>(st.nodes.size()) - 1;
}

void ExpressionParser::unexpected(State& st, const char* what) {
  if (st.tok.kind == Token::End) scanner_.error(st.span.line, st.tok.col, std::string("expected ") + what + " at the end of the expression");
  else scanner_.error(st.span.line, st.tok.col, std::string("expected ") + what + ", got '" + std::string(st.tok.text) + "'");
  throw ExprFail{};
}

ExpressionParser::Nesting ExpressionParser::nest(State& st) {
  if (st.depth + 1 > kMaxNesting) {
    scanner_.error(st.span.line, st.tok.col, "expression is nested too deeply (more than " + std::to_string(kMaxNesting) + " levels)");
    throw ExprFail{};
  }
  return Nesting{++st.depth};
}

// ---- grammar of expressions --------------------------------------------------------------

/// C's conditional `c ? a : b`, the lowest precedence (right-associative, as in C and cpfg).
int ExpressionParser::parseConditional(State& st) {
  int cond = parseBinary(st, 0);
  if (!isPunct(st, "?")) return cond;
  const Nesting nesting = nest(st);
  lex(st);
  int a = parseConditional(st);
  if (!isPunct(st, ":")) unexpected(st, "':' of 'c ? a : b'");
  lex(st);
  int b = parseConditional(st);
  return node(st, Op::Select, cond, a, b);
}

int ExpressionParser::parseBinary(State& st, int level) {
  // cpfg's grammar (lsys_input.y) puts `^` below the unary operators, left-associative:
  // in cpfg's notation `-2^2` is 4 and `2^3^2` is 64. Sprig's notation reads `^` as C's
  // pow above them, right-associative (`-2^2` is -4, `2^3^2` is 512).
  static const std::vector<std::vector<std::pair<const char*, Op>>> levels = {
      {{"||", Op::Or}},
      {{"&&", Op::And}},
      {{"==", Op::Eq}, {"!=", Op::Ne}, {"<>", Op::Ne}},
      {{"<", Op::Lt}, {"<=", Op::Le}, {">", Op::Gt}, {">=", Op::Ge}},
      {{"+", Op::Add}, {"-", Op::Sub}},
      {{"*", Op::Mul}, {"/", Op::Div}, {"%", Op::Rem}},
      {{"^", Op::Pow}},
  };
  const bool cpfg = scanner_.dialect() == Dialect::Cpfg;
  const int last = static_cast<int>(levels.size()) - (cpfg ? 0 : 1);
  if (level == last) return parseUnary(st);
  int lhs = parseBinary(st, level + 1);
  for (;;) {
    const std::pair<const char*, Op>* hit = nullptr;
    for (const auto& op : levels[level])
      if (isPunct(st, op.first)) hit = &op;
    if (!hit) return lhs;
    lex(st);
    int rhs = parseBinary(st, level + 1);
    lhs = node(st, hit->second, lhs, rhs);
  }
}

int ExpressionParser::parseUnary(State& st) {
  const Nesting nesting = nest(st);
  if (isPunct(st, "-")) {
    lex(st);
    return node(st, Op::Neg, parseUnary(st));
  }
  if (isPunct(st, "+")) {
    lex(st);
    return parseUnary(st);
  }
  if (isPunct(st, "!")) {
    lex(st);
    return node(st, Op::Not, parseUnary(st));
  }
  int base = parsePrimary(st);
  if (scanner_.dialect() == Dialect::Sprig && isPunct(st, "^")) {
    lex(st);
    return node(st, Op::Pow, base, parseUnary(st));
  }
  return base;
}

int ExpressionParser::parsePrimary(State& st) {
  if (st.tok.kind == Token::Num) {
    int n = node(st, Op::Const);
    st.nodes[n].value = st.tok.value;
    lex(st);
    return n;
  }
  if (isPunct(st, "(")) {
    lex(st);
    int inner = parseConditional(st);
    if (!isPunct(st, ")")) unexpected(st, "')'");
    lex(st);
    return inner;
  }
  if (st.tok.kind == Token::Ident) {
    Token id = st.tok;
    lex(st);
    if (isPunct(st, "(")) return parseCall(st, id);
    if (const int a = arrayId(id.text); a >= 0) {
      const int load = node(st, Op::ArrayLoad, parseIndices(st, id, a));
      st.nodes[load].var = static_cast<uint16_t>(a);
      return load;
    }
    return parseName(st, id);
  }
  unexpected(st, "a number, a name or '('");
}

/// A call `name(args)`; the current token is its `(`.
int ExpressionParser::parseCall(State& st, const Token& id) {
  std::string name(id.text);
  const FunctionInfo* fn = nullptr;
  for (const FunctionInfo& f : kFunctions)
    if (name == f.name) fn = &f;
  if (name == "srand" || name == "stop") {
    const bool ok = name == "srand" ? allowSrand_ : allowStop_;
    if (!ok) {
      scanner_.error(st.span.line, id.col,
                     name == "srand" ? std::string("cpfg's function 'srand' is supported only as a statement ('srand(s);') of a "
                                                   "'Start:', 'StartEach:', 'EndEach:' or 'End:' block, or of a rule's "
                                                   "statements in a .l file (where it reseeds cpfg's own random stream)")
                                     : std::string(allowStopReason_));
      throw ExprFail{};
    }
    static constexpr FunctionInfo kSrand{"srand", Op::Srand, 1}, kStop{"stop", Op::Stop, 1};
    fn = name == "srand" ? &kSrand : &kStop;
  }
  if (name == "func") return parseFunc(st, id);
  if (name == "curveX" || name == "curveY" || name == "curveZ" || name == "curveGAL") return parseCurve(st, id, name);
  if (!fn) {
    for (const UnsupportedFunction& u : kUnsupportedFunctions)
      if (name == u.name) {
        scanner_.error(st.span.line, id.col, "cpfg's function '" + name + "' (" + u.what + ") is not supported");
        throw ExprFail{};
      }
    std::vector<std::string> names;
    for (const FunctionInfo& f : kFunctions) names.emplace_back(f.name);
    scanner_.error(st.span.line, id.col, "unknown function '" + name + "'" + didYouMean(name, names));
    throw ExprFail{};
  }
  lex(st);
  std::vector<int> args;
  if (!isPunct(st, ")")) {
    for (;;) {
      args.push_back(parseConditional(st));
      if (isPunct(st, ",")) {
        lex(st);
        continue;
      }
      break;
    }
  }
  if (!isPunct(st, ")")) unexpected(st, "')' or ','");
  lex(st);
  if (static_cast<int>(args.size()) != fn->arity) {
    scanner_.error(st.span.line, id.col, "function '" + name + "' takes " + std::to_string(fn->arity) + " argument" +
                                             (fn->arity == 1 ? "" : "s") + ", got " + std::to_string(args.size()));
    throw ExprFail{};
  }
  // srand counts as a draw: on cpfg's streams it reseeds the stream the draws take.
  if (fn->op == Op::Ran || fn->op == Op::Nran || fn->op == Op::Bran || fn->op == Op::Biran || fn->op == Op::Srand) usesRandom_ = true;
  return node(st, fn->op, args[0], args.size() > 1 ? args[1] : -1);
}

/// cpfg's `func(n, x)`: n a number (or `#define`) naming the n-th `function:` file of the
/// view file; the current token is the `(`.
int ExpressionParser::parseFunc(State& st, const Token& id) {
  lex(st);
  const int nArg = parseConditional(st);
  if (!isPunct(st, ",")) unexpected(st, "',' (func takes 2 arguments: the function's number and x)");
  lex(st);
  const int xArg = parseConditional(st);
  if (!isPunct(st, ")")) unexpected(st, "')' (func takes 2 arguments: the function's number and x)");
  lex(st);
  const Node n = st.nodes[nArg];
  const size_t count = tables_ ? tables_->functions.size() : 0;
  if (n.op != Op::Const || n.value != std::floor(n.value) || n.value < 1 || n.value > static_cast<double>(count)) {
    scanner_.error(st.span.line, id.col,
                   count == 0 ? std::string("cpfg's func(n, x) reads the view file's function files, and it names none "
                                            "('function: NAME.func')")
                              : "func's first argument must be a number from 1 to " + std::to_string(count) +
                                    " (the view file names " + std::to_string(count) + " function file(s))");
    throw ExprFail{};
  }
  const int f = node(st, Op::Func, xArg);
  st.nodes[f].var = static_cast<uint16_t>(n.value - 1);
  return f;
}

/// cpfg's `curveX(n, t)`, `curveY(n, t)`, `curveZ(n, t)` and `curveGAL(n)`: n a number (or
/// `#define`) naming the n-th `curve:` file of the view file; the current token is the `(`.
int ExpressionParser::parseCurve(State& st, const Token& id, const std::string& name) {
  const bool gal = name == "curveGAL";
  const std::string usage = gal ? "curveGAL takes 1 argument: the curve's number" : name + " takes 2 arguments: the curve's number and t";
  lex(st);
  const int nArg = parseConditional(st);
  int tArg = -1;
  if (!gal) {
    if (!isPunct(st, ",")) unexpected(st, ("',' (" + usage + ")").c_str());
    lex(st);
    tArg = parseConditional(st);
  }
  if (!isPunct(st, ")")) unexpected(st, ("')' (" + usage + ")").c_str());
  lex(st);
  const Node n = st.nodes[nArg];
  const size_t count = tables_ ? tables_->curves.size() : 0;
  if (n.op != Op::Const || n.value != std::floor(n.value) || n.value < 1 || n.value > static_cast<double>(count)) {
    scanner_.error(st.span.line, id.col,
                   count == 0 ? "cpfg's " + name + " reads the view file's curve files, and it names none ('curve: NAME.con')"
                              : name + "'s first argument must be a number from 1 to " + std::to_string(count) +
                                    " (the view file names " + std::to_string(count) + " curve file(s))");
    throw ExprFail{};
  }
  const int f = gal ? node(st, Op::CurveLength) : node(st, Op::Curve, tArg);
  st.nodes[f].var = static_cast<uint16_t>(n.value - 1);
  st.nodes[f].value = gal ? 0 : name == "curveX" ? 0 : name == "curveY" ? 1 : 2;
  return f;
}

int ExpressionParser::arrayId(std::string_view name) const {
  if (!tables_) return -1;
  for (size_t k = 0; k < tables_->arrays.size(); ++k)
    if (tables_->arrays[k].name == name) return static_cast<int>(k);
  return -1;
}

/// The indices `[i][j]...` of cpfg's array a, named by token id (the current token is
/// after the name): a node computing the row-major flat index, each index checked.
int ExpressionParser::parseIndices(State& st, const Token& id, int a) {
  const CpfgArray& arr = tables_->arrays[static_cast<size_t>(a)];
  const std::string usage = "cpfg's array '" + arr.name + "' takes " + std::to_string(arr.dims.size()) + " ind" +
                            (arr.dims.size() == 1 ? "ex" : "ices");
  int flat = -1;
  for (size_t d = 0; d < arr.dims.size(); ++d) {
    if (!isPunct(st, "[")) {
      scanner_.error(st.span.line, d == 0 ? id.col : st.tok.col,
                     d == 0 ? usage + ": write '" + arr.name + "[i]'" : usage + ", got " + std::to_string(d));
      throw ExprFail{};
    }
    const int col = st.tok.col;
    lex(st);
    const int index = parseConditional(st);
    if (!isPunct(st, "]")) unexpected(st, "']'");
    lex(st);
    const int at = node(st, Op::ArrayAt, index);
    st.nodes[at].var = static_cast<uint16_t>(a);
    st.nodes[at].value = static_cast<double>(d);
    st.nodes[at].col = col;
    if (flat < 0) {
      flat = at;
    } else {
      const int size = node(st, Op::Const);
      st.nodes[size].value = arr.dims[d];
      flat = node(st, Op::Add, node(st, Op::Mul, flat, size), at);
    }
  }
  if (isPunct(st, "[")) {
    scanner_.error(st.span.line, st.tok.col, usage + ", got more");
    throw ExprFail{};
  }
  return flat;
}

bool ExpressionParser::emitWithinStack(const State& st, int root, size_t before, const std::string& what) {
  int depth = 0, maxDepth = 0;
  emit(st, root, depth, maxDepth);
  if (maxDepth <= kMaxStack) return true;
  scanner_.error(st.span.line, st.span.b, what + " is nested too deeply");
  code_.resize(before);
  return false;
}

std::optional<int> ExpressionParser::compileElement(Span sp, const std::vector<std::string>& vars) {
  State st(sp, vars);
  const size_t before = code_.size();
  try {
    lex(st);
    const Token id = st.tok;
    const int a = id.kind == Token::Ident ? arrayId(id.text) : -1;
    if (a < 0) unexpected(st, "the name of an array");
    lex(st);
    const int root = parseIndices(st, id, a);
    if (st.tok.kind != Token::End) unexpected(st, "'='");
    if (!emitWithinStack(st, root, before, "the index")) return std::nullopt;
    return a;
  } catch (const ExprFail&) {
    code_.resize(before);
    return std::nullopt;
  }
}

/// A formal parameter or a `#define` (in that order of precedence).
int ExpressionParser::parseName(State& st, const Token& id) {
  std::string name(id.text);
  if (st.vars) {
    auto it = std::find(st.vars->begin(), st.vars->end(), name);
    if (it != st.vars->end()) {
      int n = node(st, Op::Var);
      st.nodes[n].var = static_cast<uint16_t>(it - st.vars->begin());
      return n;
    }
  }
  if (globals_) {
    auto g = std::find(globals_->begin(), globals_->end(), name);
    if (g != globals_->end()) {
      int n = node(st, Op::Var);
      st.nodes[n].var = static_cast<uint16_t>(kMaxVars - 1 - (g - globals_->begin()));
      return n;
    }
  }
  auto d = defines_.find(name);
  if (d != defines_.end()) {
    int n = node(st, Op::Const);
    st.nodes[n].value = d->second;
    return n;
  }
  std::vector<std::string> names;
  if (st.vars) names = *st.vars;
  for (auto& [k, v] : defines_) names.push_back(k);
  scanner_.error(st.span.line, id.col, "unknown name '" + name + "'" + didYouMean(name, names));
  throw ExprFail{};
}

// ---- code --------------------------------------------------------------------------------

/// Emits node n onto code_ with constant folding; returns true when it folded to one Const.
bool ExpressionParser::emit(const State& st, int n, int& depth, int& maxDepth) {
  const Node& nd = st.nodes[n];
  int arity = arityOf(nd.op);
  if (arity == 0) {
    Instr in;
    in.op = nd.op;
    in.c = nd.value;
    in.var = nd.var;
    code_.push_back(in);
    maxDepth = std::max(maxDepth, ++depth);
    return nd.op == Op::Const;
  }
  bool allConst = true;
  for (int k = 0; k < arity; ++k) allConst &= emit(st, nd.kids[k], depth, maxDepth);
  if (nd.op == Op::ArrayAt && allConst) {
    // A constant index is checked here, at its `[`, and folded to its whole part.
    const CpfgArray& arr = tables_->arrays[nd.var];
    const int d = static_cast<int>(nd.value);
    const double v = code_.back().c, i = std::trunc(v);
    if (!(i >= 0 && i < arr.dims[static_cast<size_t>(d)])) {
      scanner_.error(st.span.line, nd.col,
                     "index " + formatNumber(v) + (arr.dims.size() > 1 ? " in dimension " + std::to_string(d + 1) : std::string()) +
                         " of cpfg's array '" + arr.name + "' is out of range (indices 0 to " +
                         std::to_string(arr.dims[static_cast<size_t>(d)] - 1) + ")");
      throw ExprFail{};
    }
    code_.back().c = i;
    return true;
  }
  Instr in;
  in.op = nd.op;
  if (nd.op == Op::Func || nd.op == Op::Curve || nd.op == Op::ArrayAt || nd.op == Op::ArrayLoad) in.var = nd.var;
  if (nd.op == Op::Curve || nd.op == Op::ArrayAt) in.c = nd.value;
  code_.push_back(in);
  depth -= arity - 1;
  if (allConst && nd.op != Op::Ran && nd.op != Op::Nran && nd.op != Op::Bran && nd.op != Op::Biran && nd.op != Op::Srand &&
      nd.op != Op::Stop && nd.op != Op::Func && nd.op != Op::Curve && nd.op != Op::ArrayLoad) {
    size_t first = code_.size() - 1 - arity;
    double v = evalCode(code_.data() + first, code_.data() + code_.size(), nullptr, nullptr);
    code_.resize(first);
    Instr c;
    c.c = v;
    code_.push_back(c);
    return true;
  }
  return false;
}

bool ExpressionParser::compile(Span sp, const std::vector<std::string>& vars, const char* what) {
  State st(sp, vars);
  const size_t before = code_.size();
  try {
    lex(st);
    int root = parseConditional(st);
    if (st.tok.kind != Token::End) unexpected(st, "an operator");
    if (!emitWithinStack(st, root, before, what)) return false;
    if (code_.size() == before + 1 && code_.back().op == Op::Const && !std::isfinite(code_.back().c)) {
      scanner_.error(sp.line, sp.b, std::string(what) + " is not finite (" + formatNumber(code_.back().c) + ")");
      code_.resize(before);
      return false;
    }
    return true;
  } catch (const ExprFail&) {
    code_.resize(before);
    return false;
  }
}

std::optional<double> ExpressionParser::constant(Span sp, const std::string& what) {
  sp = scanner_.trim(sp);
  if (sp.b == sp.e) {
    scanner_.error(sp.line, sp.b, "missing value for " + what);
    return std::nullopt;
  }
  size_t before = code_.size();
  bool rnd = usesRandom_;
  usesRandom_ = false;
  bool ok = compile(sp, kNoVars, what.c_str());
  bool drew = usesRandom_;
  usesRandom_ = rnd;
  if (!ok) return std::nullopt;
  std::optional<double> v;
  if (drew || code_.size() != before + 1) scanner_.error(sp.line, sp.b, what + " must be a constant");
  else v = code_.back().c;
  code_.resize(before);
  return v;
}

Arg ExpressionParser::compileArg(Span sp, const std::vector<std::string>& vars) {
  Arg a;
  size_t before = code_.size();
  if (!compile(sp, vars, "parameter")) return a;
  const Instr* c = code_.data() + before;
  size_t len = code_.size() - before;
  if (len == 1 && c[0].op == Op::Const) a = Arg{ArgKind::Const, 0, c[0].c, {}};
  else if (len == 1 && c[0].op == Op::Var) a = Arg{ArgKind::Var, c[0].var, 0, {}};
  else if (len == 3 && c[0].op == Op::Var && c[1].op == Op::Const && c[2].op == Op::Add) a = Arg{ArgKind::VarAddConst, c[0].var, c[1].c, {}};
  else if (len == 3 && c[0].op == Op::Var && c[1].op == Op::Const && c[2].op == Op::Sub) a = Arg{ArgKind::VarAddConst, c[0].var, -c[1].c, {}};
  else if (len == 3 && c[0].op == Op::Var && c[1].op == Op::Const && c[2].op == Op::Mul) a = Arg{ArgKind::VarMulConst, c[0].var, c[1].c, {}};
  else if (len == 3 && c[0].op == Op::Const && c[1].op == Op::Var && c[2].op == Op::Mul) a = Arg{ArgKind::VarMulConst, c[1].var, c[0].c, {}};
  else if (len == 3 && c[0].op == Op::Var && c[1].op == Op::Const && c[2].op == Op::Div) a = Arg{ArgKind::VarDivConst, c[0].var, c[1].c, {}};
  else {
    a.kind = ArgKind::Expr;
    a.code = CodeRange{static_cast<uint32_t>(before), static_cast<uint32_t>(code_.size())};
    return a;
  }
  code_.resize(before);
  return a;
}

std::optional<double> ExpressionParser::evaluate(Span sp, Rng* rng, CodeRange* deferred) {
  size_t before = code_.size();
  bool rnd = usesRandom_;
  usesRandom_ = false;
  std::optional<double> value;
  if (compile(sp, kNoVars, "parameter")) {
    // A variable here can only be one of cpfg's global variables (no formal parameters):
    // the axiom is read before any 'Start:' block runs, so it has no value yet.
    const auto global = std::find_if(code_.begin() + static_cast<std::ptrdiff_t>(before), code_.end(),
                                     [](const Instr& in) { return in.op == Op::Var || in.op == Op::Store; });
    if (global != code_.end() && deferred && global->op == Op::Var) {
      *deferred = CodeRange{static_cast<uint32_t>(before), static_cast<uint32_t>(code_.size())};
      usesRandom_ = rnd;
      return 0.0;
    }
    if (global != code_.end()) {
      const size_t k = static_cast<size_t>(kMaxVars - 1 - global->var);
      const std::string name = globals_ && k < globals_->size() ? (*globals_)[k] : std::string("?");
      scanner_.error(sp.line, sp.b, "cpfg's global variable '" + name +
                                        "' in the axiom is not supported (Sprig reads the axiom before the 'Start:' block "
                                        "assigns it): write its value");
    } else if (usesRandom_ && !rng) {
      scanner_.error(sp.line, sp.b, "random functions are not allowed here");
    } else {
      // cpfg's arrays read their initial elements here (an axiom's parameters); nothing stores.
      double* init = tables_ ? const_cast<double*>(tables_->arrayInit.data()) : nullptr;
      Draws draws{rng, nullptr};
      double v = evalCode(code_.data() + before, code_.data() + code_.size(), nullptr, rng ? &draws : nullptr, nullptr, nullptr,
                          tables_, init);
      if (std::isfinite(v)) value = v;
      else scanner_.error(sp.line, sp.b, "parameter is not finite (" + formatNumber(v) + ")");
    }
  }
  usesRandom_ = rnd;
  code_.resize(before);
  return value;
}

}  // namespace sprig::lsystem::detail
