//! Per-atom numbers computed from a formula, as OVITO's Compute property modifier and VMD's
//! `atomselect set` users make them: the speed from the velocities, a kinetic energy, a
//! distance from a point, a property masked by a condition; then coloured by or selected on
//! like any column of the file.
//!
//! # The language (OVITO's muparser expressions, with texmap's property names)
//! ```text
//! expr    := or ("?" expr ":" expr)?          -- condition ? then : else
//! or      := and ("||" and)*
//! and     := compare ("&&" compare)*
//! compare := sum (("<" | "<=" | ">" | ">=" | "==" | "!=") sum)*
//! sum     := product (("+" | "-") product)*
//! product := unary (("*" | "/") unary)*
//! unary   := ("-" | "+" | "!") unary | power
//! power   := primary ("^" unary)?             -- right-associative: 2^3^2 = 2^9; -x^2 = -(x^2)
//! primary := NUMBER | NAME | NAME "(" expr ("," expr)* ")" | "(" expr ")"
//! ```
//! Names: `x`, `y`, `z` (position, Å), `vx`, `vy`, `vz` (velocity), `index` (from 0), `id` (the
//! file's atom id, else index + 1), `mass` (u: the file's mass where it gives one, else the element's), `N` (the atom count), `pi`, and
//! every per-atom property of the frame by its name ([`Frame::property`]: `bfactor`, `charge`,
//! `c_pe`, `v_stress[1]`, or one computed earlier). Functions: `sqrt`, `abs`, `exp`, `ln` and
//! `log` (natural), `log10`, `log2`, `sin`, `cos`, `tan`, `asin`, `acos`, `atan`, `sinh`,
//! `cosh`, `tanh` (radians), `atan2(y, x)`, `pow(a, b)`, `fmod(a, b)`, `min` and `max` of any
//! number of arguments, `floor`, `ceil`, `rint` (to nearest, ties to even), `sign`. Comparisons
//! and `!`, `&&`, `||` give 1 or 0 (any non-zero value is true). Arithmetic is in f64; the
//! result is stored as f32, the precision of every property. A formula is parsed once
//! ([`Expression::parse`], errors point at the column) and evaluated per frame, one operation at
//! a time over all atoms ([`Expression::evaluate`]); a name the frame lacks is an error that
//! lists the names it has.
//!
//! ```
//! use texmap_md_io::expr::Expression;
//! use texmap_md_io::Frame;
//! let mut frame = Frame::new();
//! frame.positions = vec![[3.0, 4.0, 0.0], [0.0, 0.0, 2.0]];
//! frame.velocities = vec![[1.0, 2.0, 2.0], [0.0, 0.0, 0.5]];
//! let speed = Expression::parse("sqrt(vx^2 + vy^2 + vz^2)").unwrap();
//! assert_eq!(speed.evaluate(&frame).unwrap(), [3.0, 0.5]);
//! let far = Expression::parse("sqrt(x*x + y*y + z*z) > 4 ? index : -1").unwrap();
//! assert_eq!(far.evaluate(&frame).unwrap(), [0.0, -1.0]);
//! let e = Expression::parse("2 * (x + ").unwrap_err();
//! assert_eq!(e.to_string(), "column 10: expected a number, a name or '(', found the end of the formula");
//! ```

use std::fmt;

use crate::frame::Frame;

/// A parsed formula (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Expression {
    root: Node,
    text: String,
}

/// Why a formula cannot be parsed or evaluated.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ExprError {
    /// The 1-based column of the offending token (parse errors), or 0.
    pub column: usize,
    /// What is wrong.
    pub message: String,
}

impl fmt::Display for ExprError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.column > 0 {
            write!(f, "column {}: {}", self.column, self.message)
        } else {
            write!(f, "{}", self.message)
        }
    }
}

impl std::error::Error for ExprError {}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Op {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
    Lt,
    Le,
    Gt,
    Ge,
    Eq,
    Ne,
    And,
    Or,
}

#[derive(Clone, Debug, PartialEq)]
enum Node {
    Number(f64),
    Name(String),
    Neg(Box<Node>),
    Not(Box<Node>),
    Binary(Op, Box<Node>, Box<Node>),
    If(Box<Node>, Box<Node>, Box<Node>),
    Call(String, Vec<Node>),
}

/// Functions and their argument counts (`None`: one or more).
const FUNCTIONS: &[(&str, Option<usize>)] = &[
    ("sqrt", Some(1)),
    ("abs", Some(1)),
    ("exp", Some(1)),
    ("ln", Some(1)),
    ("log", Some(1)),
    ("log10", Some(1)),
    ("log2", Some(1)),
    ("sin", Some(1)),
    ("cos", Some(1)),
    ("tan", Some(1)),
    ("asin", Some(1)),
    ("acos", Some(1)),
    ("atan", Some(1)),
    ("sinh", Some(1)),
    ("cosh", Some(1)),
    ("tanh", Some(1)),
    ("floor", Some(1)),
    ("ceil", Some(1)),
    ("rint", Some(1)),
    ("sign", Some(1)),
    ("atan2", Some(2)),
    ("pow", Some(2)),
    ("fmod", Some(2)),
    ("min", None),
    ("max", None),
];

/// The longest formula taken, in bytes (a formula is typed, not generated).
const MAX_LEN: usize = 4096;
/// The deepest nesting taken (parentheses, operators), so that no formula exhausts the stack.
const MAX_DEPTH: usize = 64;

impl Expression {
    /// Parses `text` (see the module docs).
    pub fn parse(text: &str) -> Result<Expression, ExprError> {
        if text.len() > MAX_LEN {
            return Err(ExprError {
                column: 0,
                message: format!("the formula is {} bytes long, over {MAX_LEN}", text.len()),
            });
        }
        let mut p = Parser {
            tokens: tokenize(text)?,
            at: 0,
            depth: 0,
            len: text.chars().count(),
        };
        let root = p.expr()?;
        if let Some(t) = p.tokens.get(p.at) {
            return Err(ExprError {
                column: t.column,
                message: format!("unexpected {}", t.kind.describe()),
            });
        }
        Ok(Expression {
            root,
            text: text.to_string(),
        })
    }

    /// The formula as written.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The formula's value for every atom of `frame`.
    pub fn evaluate(&self, frame: &Frame) -> Result<Vec<f32>, ExprError> {
        let values = eval(&self.root, frame)?;
        let n = frame.n_atoms();
        Ok(match values {
            Column::Scalar(v) => vec![v as f32; n],
            Column::Atoms(v) => v.into_iter().map(|x| x as f32).collect(),
        })
    }
}

#[derive(Clone, Debug, PartialEq)]
enum TokenKind {
    Number(f64),
    Name(String),
    /// An operator or punctuation, as written.
    Symbol(&'static str),
}

impl TokenKind {
    fn describe(&self) -> String {
        match self {
            TokenKind::Number(v) => format!("number {v}"),
            TokenKind::Name(n) => format!("name '{n}'"),
            TokenKind::Symbol(s) => format!("'{s}'"),
        }
    }
}

#[derive(Clone, Debug)]
struct Token {
    kind: TokenKind,
    column: usize,
}

const SYMBOLS: &[&str] = &[
    "<=", ">=", "==", "!=", "&&", "||", "<", ">", "+", "-", "*", "/", "^", "!", "?", ":", "(", ")",
    ",",
];

fn tokenize(text: &str) -> Result<Vec<Token>, ExprError> {
    let chars: Vec<char> = text.chars().collect();
    let mut tokens = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let column = i + 1;
        if c.is_whitespace() {
            i += 1;
        } else if c.is_ascii_digit()
            || (c == '.' && chars.get(i + 1).is_some_and(|d| d.is_ascii_digit()))
        {
            let start = i;
            while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
                i += 1;
            }
            // An exponent: e or E, an optional sign, digits.
            if i < chars.len() && (chars[i] == 'e' || chars[i] == 'E') {
                let mut j = i + 1;
                if j < chars.len() && (chars[j] == '+' || chars[j] == '-') {
                    j += 1;
                }
                if j < chars.len() && chars[j].is_ascii_digit() {
                    while j < chars.len() && chars[j].is_ascii_digit() {
                        j += 1;
                    }
                    i = j;
                }
            }
            let word: String = chars[start..i].iter().collect();
            let value = word.parse::<f64>().map_err(|_| ExprError {
                column,
                message: format!("'{word}' is not a number"),
            })?;
            tokens.push(Token {
                kind: TokenKind::Number(value),
                column,
            });
        } else if c.is_alphabetic() || c == '_' {
            let start = i;
            while i < chars.len() {
                let d = chars[i];
                if d.is_alphanumeric() || d == '_' || d == '.' {
                    i += 1;
                } else if d == '[' {
                    // A LAMMPS column such as v_stress[1]: the bracketed index is part of the name.
                    let close = chars[i..].iter().position(|&e| e == ']');
                    match close {
                        Some(k)
                            if chars[i + 1..i + k].iter().all(|e| e.is_ascii_digit()) && k > 1 =>
                        {
                            i += k + 1
                        }
                        _ => {
                            return Err(ExprError {
                                column: i + 1,
                                message: "expected a column index such as [1] after a name".into(),
                            });
                        }
                    }
                } else {
                    break;
                }
            }
            tokens.push(Token {
                kind: TokenKind::Name(chars[start..i].iter().collect()),
                column,
            });
        } else {
            let rest: String = chars[i..chars.len().min(i + 2)].iter().collect();
            let Some(symbol) = SYMBOLS.iter().find(|s| rest.starts_with(**s)) else {
                return Err(ExprError {
                    column,
                    message: format!("unexpected character '{c}'"),
                });
            };
            tokens.push(Token {
                kind: TokenKind::Symbol(symbol),
                column,
            });
            i += symbol.chars().count();
        }
    }
    Ok(tokens)
}

struct Parser {
    tokens: Vec<Token>,
    at: usize,
    depth: usize,
    /// The formula's length in characters (the column past its end).
    len: usize,
}

impl Parser {
    fn peek(&self) -> Option<&TokenKind> {
        self.tokens.get(self.at).map(|t| &t.kind)
    }

    fn column(&self) -> usize {
        self.tokens.get(self.at).map_or(self.len + 1, |t| t.column)
    }

    fn eat(&mut self, symbol: &str) -> bool {
        if matches!(self.peek(), Some(TokenKind::Symbol(s)) if *s == symbol) {
            self.at += 1;
            true
        } else {
            false
        }
    }

    fn expect(&mut self, symbol: &str) -> Result<(), ExprError> {
        if self.eat(symbol) {
            Ok(())
        } else {
            Err(self.error(format!("expected '{symbol}'")))
        }
    }

    fn error(&self, what: String) -> ExprError {
        let found = match self.tokens.get(self.at) {
            Some(t) => t.kind.describe(),
            None => "the end of the formula".to_string(),
        };
        ExprError {
            column: self.column(),
            message: format!("{what}, found {found}"),
        }
    }

    fn expr(&mut self) -> Result<Node, ExprError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(ExprError {
                column: self.column(),
                message: format!("the formula nests deeper than {MAX_DEPTH} levels"),
            });
        }
        let condition = self.or()?;
        let node = if self.eat("?") {
            let then = self.expr()?;
            self.expect(":")?;
            let otherwise = self.expr()?;
            Node::If(Box::new(condition), Box::new(then), Box::new(otherwise))
        } else {
            condition
        };
        self.depth -= 1;
        Ok(node)
    }

    /// One level of left-associative binary operators over `next`.
    fn binary(
        &mut self,
        ops: &[(&str, Op)],
        next: fn(&mut Parser) -> Result<Node, ExprError>,
    ) -> Result<Node, ExprError> {
        let mut left = next(self)?;
        'outer: loop {
            for (symbol, op) in ops {
                if self.eat(symbol) {
                    let right = next(self)?;
                    left = Node::Binary(*op, Box::new(left), Box::new(right));
                    continue 'outer;
                }
            }
            return Ok(left);
        }
    }

    fn or(&mut self) -> Result<Node, ExprError> {
        self.binary(&[("||", Op::Or)], Parser::and)
    }

    fn and(&mut self) -> Result<Node, ExprError> {
        self.binary(&[("&&", Op::And)], Parser::compare)
    }

    fn compare(&mut self) -> Result<Node, ExprError> {
        self.binary(
            &[
                ("<=", Op::Le),
                (">=", Op::Ge),
                ("==", Op::Eq),
                ("!=", Op::Ne),
                ("<", Op::Lt),
                (">", Op::Gt),
            ],
            Parser::sum,
        )
    }

    fn sum(&mut self) -> Result<Node, ExprError> {
        self.binary(&[("+", Op::Add), ("-", Op::Sub)], Parser::product)
    }

    fn product(&mut self) -> Result<Node, ExprError> {
        self.binary(&[("*", Op::Mul), ("/", Op::Div)], Parser::unary)
    }

    fn unary(&mut self) -> Result<Node, ExprError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(ExprError {
                column: self.column(),
                message: format!("the formula nests deeper than {MAX_DEPTH} levels"),
            });
        }
        let node = if self.eat("-") {
            Node::Neg(Box::new(self.unary()?))
        } else if self.eat("+") {
            self.unary()?
        } else if self.eat("!") {
            Node::Not(Box::new(self.unary()?))
        } else {
            let base = self.primary()?;
            if self.eat("^") {
                Node::Binary(Op::Pow, Box::new(base), Box::new(self.unary()?))
            } else {
                base
            }
        };
        self.depth -= 1;
        Ok(node)
    }

    fn primary(&mut self) -> Result<Node, ExprError> {
        let column = self.column();
        match self.peek().cloned() {
            Some(TokenKind::Number(v)) => {
                self.at += 1;
                Ok(Node::Number(v))
            }
            Some(TokenKind::Name(name)) => {
                self.at += 1;
                if !self.eat("(") {
                    return Ok(Node::Name(name));
                }
                let Some(&(_, arity)) = FUNCTIONS.iter().find(|f| f.0 == name) else {
                    let names: Vec<&str> = FUNCTIONS.iter().map(|f| f.0).collect();
                    return Err(ExprError {
                        column,
                        message: format!("'{name}' is not a function ({})", names.join(", ")),
                    });
                };
                let mut args = vec![self.expr()?];
                while self.eat(",") {
                    args.push(self.expr()?);
                }
                self.expect(")")?;
                if arity.is_some_and(|a| a != args.len()) {
                    return Err(ExprError {
                        column,
                        message: format!(
                            "{name} takes {} argument(s), not {}",
                            arity.unwrap_or(1),
                            args.len()
                        ),
                    });
                }
                Ok(Node::Call(name, args))
            }
            Some(TokenKind::Symbol("(")) => {
                self.at += 1;
                let inner = self.expr()?;
                self.expect(")")?;
                Ok(inner)
            }
            _ => Err(self.error("expected a number, a name or '('".into())),
        }
    }
}

/// A value per atom, or one for all.
enum Column {
    Scalar(f64),
    Atoms(Vec<f64>),
}

impl Column {
    fn map(self, f: impl Fn(f64) -> f64) -> Column {
        match self {
            Column::Scalar(v) => Column::Scalar(f(v)),
            Column::Atoms(mut v) => {
                v.iter_mut().for_each(|x| *x = f(*x));
                Column::Atoms(v)
            }
        }
    }

    fn zip(self, other: Column, f: impl Fn(f64, f64) -> f64) -> Column {
        match (self, other) {
            (Column::Scalar(a), Column::Scalar(b)) => Column::Scalar(f(a, b)),
            (Column::Atoms(mut a), Column::Scalar(b)) => {
                a.iter_mut().for_each(|x| *x = f(*x, b));
                Column::Atoms(a)
            }
            (Column::Scalar(a), Column::Atoms(mut b)) => {
                b.iter_mut().for_each(|x| *x = f(a, *x));
                Column::Atoms(b)
            }
            (Column::Atoms(mut a), Column::Atoms(b)) => {
                a.iter_mut().zip(b).for_each(|(x, y)| *x = f(*x, y));
                Column::Atoms(a)
            }
        }
    }
}

fn truth(v: bool) -> f64 {
    if v { 1.0 } else { 0.0 }
}

fn eval(node: &Node, frame: &Frame) -> Result<Column, ExprError> {
    Ok(match node {
        Node::Number(v) => Column::Scalar(*v),
        Node::Name(name) => variable(name, frame)?,
        Node::Neg(a) => eval(a, frame)?.map(|x| -x),
        Node::Not(a) => eval(a, frame)?.map(|x| truth(x == 0.0)),
        Node::Binary(op, a, b) => {
            let (a, b) = (eval(a, frame)?, eval(b, frame)?);
            match op {
                Op::Add => a.zip(b, |x, y| x + y),
                Op::Sub => a.zip(b, |x, y| x - y),
                Op::Mul => a.zip(b, |x, y| x * y),
                Op::Div => a.zip(b, |x, y| x / y),
                Op::Pow => a.zip(b, f64::powf),
                Op::Lt => a.zip(b, |x, y| truth(x < y)),
                Op::Le => a.zip(b, |x, y| truth(x <= y)),
                Op::Gt => a.zip(b, |x, y| truth(x > y)),
                Op::Ge => a.zip(b, |x, y| truth(x >= y)),
                Op::Eq => a.zip(b, |x, y| truth(x == y)),
                Op::Ne => a.zip(b, |x, y| truth(x != y)),
                Op::And => a.zip(b, |x, y| truth(x != 0.0 && y != 0.0)),
                Op::Or => a.zip(b, |x, y| truth(x != 0.0 || y != 0.0)),
            }
        }
        Node::If(c, a, b) => {
            // Both branches are computed (no side effects); the condition picks per atom.
            let (c, a, b) = (eval(c, frame)?, eval(a, frame)?, eval(b, frame)?);
            match c {
                Column::Scalar(c) => {
                    if c != 0.0 {
                        a
                    } else {
                        b
                    }
                }
                Column::Atoms(c) => {
                    let (a, b) = (expand(a, c.len()), expand(b, c.len()));
                    Column::Atoms(
                        c.iter()
                            .enumerate()
                            .map(|(i, &c)| if c != 0.0 { a[i] } else { b[i] })
                            .collect(),
                    )
                }
            }
        }
        Node::Call(name, args) => {
            let mut values = Vec::with_capacity(args.len());
            for a in args {
                values.push(eval(a, frame)?);
            }
            let mut values = values.into_iter();
            let first = values.next().expect("a call has an argument");
            match name.as_str() {
                "atan2" => first.zip(values.next().expect("two"), f64::atan2),
                "pow" => first.zip(values.next().expect("two"), f64::powf),
                "fmod" => first.zip(values.next().expect("two"), |a, b| a % b),
                "min" => values.fold(first, |acc, v| acc.zip(v, f64::min)),
                "max" => values.fold(first, |acc, v| acc.zip(v, f64::max)),
                one => {
                    let f: fn(f64) -> f64 = match one {
                        "sqrt" => f64::sqrt,
                        "abs" => f64::abs,
                        "exp" => f64::exp,
                        "ln" | "log" => f64::ln,
                        "log10" => f64::log10,
                        "log2" => f64::log2,
                        "sin" => f64::sin,
                        "cos" => f64::cos,
                        "tan" => f64::tan,
                        "asin" => f64::asin,
                        "acos" => f64::acos,
                        "atan" => f64::atan,
                        "sinh" => f64::sinh,
                        "cosh" => f64::cosh,
                        "tanh" => f64::tanh,
                        "floor" => f64::floor,
                        "ceil" => f64::ceil,
                        "rint" => f64::round_ties_even,
                        _ => |v: f64| {
                            if v > 0.0 {
                                1.0
                            } else if v < 0.0 {
                                -1.0
                            } else {
                                v
                            }
                        },
                    };
                    first.map(f)
                }
            }
        }
    })
}

fn expand(c: Column, n: usize) -> Vec<f64> {
    match c {
        Column::Scalar(v) => vec![v; n],
        Column::Atoms(v) => v,
    }
}

/// The column a name stands for in `frame`.
fn variable(name: &str, frame: &Frame) -> Result<Column, ExprError> {
    let n = frame.n_atoms();
    let axis = |k: usize, of: &[[f32; 3]]| Column::Atoms(of.iter().map(|p| p[k] as f64).collect());
    if let Some(p) = frame.property(name) {
        return Ok(Column::Atoms(p.iter().map(|v| *v as f64).collect()));
    }
    Ok(match name {
        "x" => axis(0, &frame.positions),
        "y" => axis(1, &frame.positions),
        "z" => axis(2, &frame.positions),
        "vx" | "vy" | "vz" if frame.velocities.len() == n && n > 0 => {
            axis(usize::from(name.as_bytes()[1] - b'x'), &frame.velocities)
        }
        "index" => Column::Atoms((0..n).map(|i| i as f64).collect()),
        "id" if frame.ids.len() == n => {
            Column::Atoms(frame.ids.iter().map(|v| *v as f64).collect())
        }
        "id" => Column::Atoms((0..n).map(|i| i as f64 + 1.0).collect()),
        "mass" => Column::Atoms((0..n).map(|i| crate::atom_mass(frame, i)).collect()),
        "N" => Column::Scalar(n as f64),
        "pi" => Column::Scalar(std::f64::consts::PI),
        _ => {
            let mut names: Vec<String> = ["x", "y", "z", "index", "id", "mass", "N", "pi"]
                .map(String::from)
                .to_vec();
            if frame.velocities.len() == n && n > 0 {
                names.extend(["vx", "vy", "vz"].map(String::from));
            }
            names.extend(frame.properties.iter().map(|p| p.name.clone()));
            return Err(ExprError {
                column: 0,
                message: format!("the frame has no '{name}' (it has: {})", names.join(", ")),
            });
        }
    })
}
