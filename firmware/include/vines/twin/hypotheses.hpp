// The damage test over hypotheses (docs/twin.md section 5): given the
// stories' estimated losses theta and the covariance Sigma of their error
// (the estimate's own, the model's, the baseline's), the generalised
// likelihood ratio of "story j lost stiffness" and of "stories a and b lost
// stiffness" against "nothing changed", with each hypothesis' size by
// generalised least squares. Fixed capacity N, no heap; S double or float.
#pragma once

#include <cmath>

namespace vines::twin {

// Cholesky of the leading n x n of A in place (lower triangle); false if A
// is not positive definite.
template <typename S, int N>
bool cholesky(S (&A)[N][N], int n) {
  for (int a = 0; a < n; ++a)
    for (int b = 0; b <= a; ++b) {
      S t = A[a][b];
      for (int c = 0; c < b; ++c) t -= A[a][c] * A[b][c];
      if (a == b) {
        if (!(t > S(0))) return false;
        A[a][a] = std::sqrt(t);
      } else {
        A[a][b] = t / A[b][b];
      }
    }
  return true;
}

// x <- (F F^T)^-1 x, F the lower factor of the leading n x n (forward, then
// back substitution).
template <typename S, int N>
void solve_from_factor(const S (&F)[N][N], int n, S* x) {
  for (int a = 0; a < n; ++a) {
    S t = x[a];
    for (int c = 0; c < a; ++c) t -= F[a][c] * x[c];
    x[a] = t / F[a][a];
  }
  for (int a = n - 1; a >= 0; --a) {
    S t = x[a];
    for (int c = a + 1; c < n; ++c) t -= F[c][a] * x[c];
    x[a] = t / F[a][a];
  }
}

// The inverse P = (F F^T)^-1 from the lower factor F (leading n x n): the
// inverse of F column by column, then its Gram matrix.
template <typename S, int N>
void inverse_from_factor(const S (&F)[N][N], int n, S (&P)[N][N]) {
  S V[N][N];  // V = F^-1, lower
  for (int c = 0; c < n; ++c)
    for (int r = 0; r < n; ++r) {
      if (r < c) {
        V[r][c] = S(0);
        continue;
      }
      S t = r == c ? S(1) : S(0);
      for (int k = c; k < r; ++k) t -= F[r][k] * V[k][c];
      V[r][c] = t / F[r][r];
    }
  for (int a = 0; a < n; ++a)
    for (int b = 0; b <= a; ++b) {
      S t(0);
      for (int k = a; k < n; ++k) t += V[k][a] * V[k][b];
      P[a][b] = P[b][a] = t;
    }
}

// The best explanations of theta under precision P = Sigma^-1.
template <typename S, int N>
struct Hypotheses {
  S stat[N] = {};      // each story's one-story statistic (0 where its size is a gain)
  S size[N] = {};      // each story's size under its own hypothesis
  int story = -1;      // the best single story...
  S one = S(0);        // ...its statistic
  S runner = S(0);     // the best other story's statistic
  int a = -1, b = -1;  // the best pair (both losses)...
  S two = S(0);        // ...its statistic
  S size_a = S(0), size_b = S(0);
  S total = S(0);      // theta' P theta: the statistic of every story free
};

// One story j: u = P theta, statistic u_j^2 / P_jj, size u_j / P_jj. Two
// stories a, b: the 2 x 2 block of P solved for both sizes, statistic
// u_ab . size_ab. Only losses count (a story does not stiffen in an
// earthquake).
template <typename S, int N>
void test_hypotheses(const S (&P)[N][N], const S* theta, int n, Hypotheses<S, N>* h) {
  S u[N];
  for (int a = 0; a < n; ++a) {
    S t(0);
    for (int b = 0; b < n; ++b) t += P[a][b] * theta[b];
    u[a] = t;
  }
  *h = Hypotheses<S, N>{};
  for (int a = 0; a < n; ++a) h->total += u[a] * theta[a];
  for (int j = 0; j < n; ++j) {
    h->size[j] = u[j] / P[j][j];
    h->stat[j] = u[j] > S(0) ? u[j] * h->size[j] : S(0);
    if (h->stat[j] > h->one) h->runner = h->one, h->one = h->stat[j], h->story = j;
    else if (h->stat[j] > h->runner) h->runner = h->stat[j];
  }
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b < n; ++b) {
      const S det = P[a][a] * P[b][b] - P[a][b] * P[a][b];
      if (!(det > S(0))) continue;
      const S da = (P[b][b] * u[a] - P[a][b] * u[b]) / det, db = (P[a][a] * u[b] - P[a][b] * u[a]) / det;
      if (!(da > S(0) && db > S(0))) continue;
      const S t = u[a] * da + u[b] * db;
      if (t > h->two) h->two = t, h->a = a, h->b = b, h->size_a = da, h->size_b = db;
    }
}

}  // namespace vines::twin
