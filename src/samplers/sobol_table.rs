//! Sobol' direction-number initializers.
//!
//! Source: S. Joe and F. Y. Kuo, "Constructing Sobol sequences with better
//! two-dimensional projections", SIAM J. Sci. Comput. 30 (2008) 2635–2654;
//! table `new-joe-kuo-6.21201`, dimensions 2–21 (dimension 1 is the van der
//! Corput sequence, all m_k = 1). The table is published under a BSD-style
//! licence by its authors (https://web.maths.unsw.edu.au/~fkuo/sobol/).
//!
//! Each row: (s, a, m_1..m_s) — s the degree of the primitive polynomial
//! x^s + a_1 x^(s−1) + … + a_(s−1) x + 1 whose middle coefficients are the
//! bits of a (a_1 most significant), and the initial odd m_k < 2^k.

/// (degree s, coefficients a, initial m_1..m_s) for dimensions 2, 3, ….
pub(super) const JOE_KUO: &[(u32, u32, &[u32])] = &[
    (1, 0, &[1]),
    (2, 1, &[1, 3]),
    (3, 1, &[1, 3, 1]),
    (3, 2, &[1, 1, 1]),
    (4, 1, &[1, 1, 3, 3]),
    (4, 4, &[1, 3, 5, 13]),
    (5, 2, &[1, 1, 5, 5, 17]),
    (5, 4, &[1, 1, 5, 5, 5]),
    (5, 7, &[1, 1, 7, 11, 19]),
    (5, 11, &[1, 1, 5, 1, 1]),
    (5, 13, &[1, 1, 1, 3, 11]),
    (5, 14, &[1, 3, 5, 5, 31]),
    (6, 1, &[1, 3, 3, 9, 7, 49]),
    (6, 13, &[1, 1, 1, 15, 21, 21]),
    (6, 16, &[1, 3, 1, 13, 27, 49]),
    (6, 19, &[1, 1, 1, 15, 7, 5]),
    (6, 22, &[1, 3, 1, 15, 13, 25]),
    (6, 25, &[1, 1, 5, 5, 19, 61]),
    (7, 1, &[1, 3, 7, 11, 23, 15, 103]),
    (7, 4, &[1, 3, 7, 13, 13, 15, 69]),
];
