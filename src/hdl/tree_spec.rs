//! What an adder tree stands for, stated by the plan that builds it: a sum of products
//! `a * b << shift` plus a rounding constant, over the tree's own input signals. The formal
//! proof of the multipliers (`rmapgen prove-mult`, `prove::mult`) reads this and
//! writes it as plain Verilog arithmetic (`a * b + c`), never as the tree's terms or nodes,
//! so a term left out or a node built wrong cannot hide in the specification.

use super::adder_tree::{Sig, Sum};

/// The second factor of a product: a signal or a constant.
#[derive(Clone, Debug)]
pub enum Factor {
    Sig(Sig),
    Const(u128),
}

/// `a * b << shift`.
#[derive(Clone, Debug)]
pub struct Product {
    pub a: Sig,
    pub b: Factor,
    pub shift: u32,
}

/// The proof's case split: `sig` takes every value in `0..=last` in turn (a constant factor
/// makes the product a sum of shifted copies, which the SAT solver proves quickly, where two
/// symbolic factors would not finish); `complement` is a signal the stage derives as
/// `total - sig` (interpolate's weight pair), set with it.
#[derive(Clone, Debug)]
pub struct Split {
    pub sig: Sig,
    pub last: u128,
    pub complement: Option<(Sig, u128)>,
}

/// One adder tree's specification.
#[derive(Clone, Debug)]
pub struct TreeSpec {
    /// The tree's name (the prefix of its nodes, `pa`).
    pub tree: String,
    /// What it computes, in words and symbols, for messages.
    pub title: String,
    pub products: Vec<Product>,
    pub constant: u128,
    /// The signal holding the tree's result in the stage.
    pub sum: Sum,
    /// The premises of a bounded tree ([`super::adder_tree::Tree::bound`]): inputs that the
    /// stage keeps at or below a value (proved elsewhere: see docs/VERIFICATION.md).
    pub at_most: Vec<(Sig, u128)>,
    pub split: Option<Split>,
}

impl TreeSpec {
    /// `a * b + constant` with both factors signals; the split enumerates the narrower.
    pub fn product(tree: &str, title: &str, a: Sig, b: Sig, constant: u128, sum: Sum) -> Self {
        let (n, other) = if a.width <= b.width {
            (a.clone(), b.clone())
        } else {
            (b.clone(), a.clone())
        };
        TreeSpec {
            tree: tree.into(),
            title: title.into(),
            products: vec![Product {
                a: other,
                b: Factor::Sig(n.clone()),
                shift: 0,
            }],
            constant,
            sum,
            at_most: Vec::new(),
            split: Some(Split {
                last: (1u128 << n.width) - 1,
                sig: n,
                complement: None,
            }),
        }
    }

    /// Every input signal the specification reads (each once), in order of appearance.
    pub fn inputs(&self) -> Vec<Sig> {
        let mut v: Vec<Sig> = Vec::new();
        let mut add = |s: &Sig| {
            if !v.iter().any(|x| x.name == s.name) {
                v.push(s.clone());
            }
        };
        for p in &self.products {
            add(&p.a);
            if let Factor::Sig(s) = &p.b {
                add(s);
            }
        }
        if let Some((s, _)) = self.split.as_ref().and_then(|s| s.complement.as_ref()) {
            add(s);
        }
        v
    }

    /// The largest value of an input under the premises.
    fn max_of(&self, s: &Sig) -> u128 {
        let full = (1u128 << s.width) - 1;
        self.at_most
            .iter()
            .find(|(x, _)| x.name == s.name)
            .map_or(full, |&(_, m)| m.min(full))
    }

    /// The largest value of the specified sum (ignoring the weight pair's coupling: an upper
    /// bound, for the width the proof computes it in).
    pub fn max(&self) -> u128 {
        self.products
            .iter()
            .map(|p| {
                let b = match &p.b {
                    Factor::Sig(s) => self.max_of(s),
                    Factor::Const(k) => *k,
                };
                (self.max_of(&p.a) * b) << p.shift
            })
            .sum::<u128>()
            + self.constant
    }
}
