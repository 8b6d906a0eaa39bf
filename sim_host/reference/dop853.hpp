// Dormand-Prince 8(5,3) explicit Runge-Kutta step (Hairer, Norsett, Wanner,
// "Solving ODEs I", DOP853), coefficients to 30 digits, in any scalar T.
// The error estimate combines the 5th- and 3rd-order embedded solutions as in
// Hairer's code: err = h |e5|^2 / sqrt(|e5|^2 + 0.01 |e3|^2) (RMS norms).
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

namespace vines::host::reference {

struct Dop853Table {
  static constexpr int kStages = 12;
  static constexpr long double c[kStages] = {
      0.0L, 0.526001519587677318785587544488e-01L, 0.789002279381515978178381316732e-01L,
      0.118350341907227396726757197510L, 0.281649658092772603273242802490L, 1.0L / 3.0L, 0.25L,
      4.0L / 13.0L, 127.0L / 195.0L, 0.6L, 6.0L / 7.0L, 1.0L};
  // a[i][j], j < i; row 12 is b (the 8th-order weights).
  static constexpr long double a[kStages + 1][kStages] = {
      {},
      {5.26001519587677318785587544488e-2L},
      {1.97250569845378994544595329183e-2L, 5.91751709536136983633785987549e-2L},
      {2.95875854768068491816892993775e-2L, 0, 8.87627564304205475450678981324e-2L},
      {2.41365134159266685502369798665e-1L, 0, -8.84549479328286085344864962717e-1L,
       9.24834003261792003115737966543e-1L},
      {1.0L / 27.0L, 0, 0, 1.70828608729473871279604482173e-1L, 1.25467687566822425016691814123e-1L},
      {3.7109375e-2L, 0, 0, 1.70252211019544039314978060272e-1L, 6.02165389804559606850219397283e-2L,
       -1.7578125e-2L},
      {3.70920001185047927108779319836e-2L, 0, 0, 1.70383925712239993810214054705e-1L,
       1.07262030446373284651809199168e-1L, -1.53194377486244017527936158236e-2L,
       8.27378916381402288758473766002e-3L},
      {6.24110958716075717114429577812e-1L, 0, 0, -3.36089262944694129406857109825L,
       -8.68219346841726006818189891453e-1L, 2.75920996994467083049415600797e1L,
       2.01540675504778934086186788979e1L, -4.34898841810699588477366255144e1L},
      {4.77662536438264365890433908527e-1L, 0, 0, -2.48811461997166764192642586468L,
       -5.90290826836842996371446475743e-1L, 2.12300514481811942347288949897e1L,
       1.52792336328824235832596922938e1L, -3.32882109689848629194453265587e1L,
       -2.03312017085086261358222928593e-2L},
      {-9.3714243008598732571704021658e-1L, 0, 0, 5.18637242884406370830023853209L,
       1.09143734899672957818500254654L, -8.14978701074692612513997267357L,
       -1.85200656599969598641566180701e1L, 2.27394870993505042818970056734e1L,
       2.49360555267965238987089396762L, -3.0467644718982195003823669022L},
      {2.27331014751653820792359768449L, 0, 0, -1.05344954667372501984066689879e1L,
       -2.00087205822486249909675718444L, -1.79589318631187989172765950534e1L,
       2.79488845294199600508499808837e1L, -2.85899827713502369474065508674L,
       -8.87285693353062954433549289258L, 1.23605671757943030647266201528e1L,
       6.43392746015763530355970484046e-1L},
      {5.42937341165687622380535766363e-2L, 0, 0, 0, 0, 4.45031289275240888144113950566L,
       1.89151789931450038304281599044L, -5.8012039600105847814672114227L,
       3.1116436695781989440891606237e-1L, -1.52160949662516078556178806805e-1L,
       2.01365400804030348374776537501e-1L, 4.47106157277725905176885569043e-2L}};
  // b minus the 3rd-order weights (stages 0..11), and the 5th-order error weights.
  static constexpr long double e3[kStages] = {
      5.42937341165687622380535766363e-2L - 0.244094488188976377952755905512L, 0, 0, 0, 0,
      4.45031289275240888144113950566L, 1.89151789931450038304281599044L,
      -5.8012039600105847814672114227L,
      3.1116436695781989440891606237e-1L - 0.733846688281611857341361741547L,
      -1.52160949662516078556178806805e-1L, 2.01365400804030348374776537501e-1L,
      4.47106157277725905176885569043e-2L - 0.220588235294117647058823529412e-1L};
  static constexpr long double e5[kStages] = {
      0.1312004499419488073250102996e-1L, 0, 0, 0, 0, -0.1225156446376204440720569753e1L,
      -0.4957589496572501915214079952L, 0.1664377182454986536961530415e1L,
      -0.3503288487499736816886487290L, 0.3341791187130174790297318841L,
      0.8192320648511571246570742613e-1L, -0.2235530786388629525884427845e-1L};
};

// One DOP853 step; owns its stage storage. rhs(s, y, dy) with local time s.
template <typename T>
class Dop853 {
 public:
  explicit Dop853(int n) : n_(n), tmp_(static_cast<std::size_t>(n)) {
    for (auto& k : k_) k.resize(static_cast<std::size_t>(n));
  }

  // From (s, y) with f0 = f(s, y), a step of size h: y1 = y(s + h), f1 =
  // f(s + h, y1). Returns the error norm against atol + rtol max(|y|, |y1|)
  // (<= 1: acceptable).
  template <class Rhs>
  T step(Rhs& rhs, T s, const T* y, const T* f0, T h, T rtol, const T* atol, T* y1, T* f1) {
    using Tab = Dop853Table;
    const std::size_t n = static_cast<std::size_t>(n_);
    std::copy(f0, f0 + n_, k_[0].begin());
    for (int i = 1; i <= Tab::kStages; ++i) {
      T* out = i < Tab::kStages ? tmp_.data() : y1;
      for (std::size_t q = 0; q < n; ++q) {
        T acc = T(0);
        for (int j = 0; j < i; ++j)
          if (Tab::a[i][j] != 0.0L) acc += T(Tab::a[i][j]) * k_[static_cast<std::size_t>(j)][q];
        out[q] = y[q] + h * acc;
      }
      if (i < Tab::kStages) rhs(s + T(Tab::c[i]) * h, tmp_.data(), k_[static_cast<std::size_t>(i)].data());
    }
    rhs(s + h, y1, f1);
    T e5 = T(0), e3 = T(0);
    for (std::size_t q = 0; q < n; ++q) {
      T d5 = T(0), d3 = T(0);
      for (int j = 0; j < Tab::kStages; ++j) {
        d5 += T(Tab::e5[j]) * k_[static_cast<std::size_t>(j)][q];
        d3 += T(Tab::e3[j]) * k_[static_cast<std::size_t>(j)][q];
      }
      using std::fabs;
      const T sc = atol[q] + rtol * std::max(fabs(y[q]), fabs(y1[q]));
      e5 += (d5 / sc) * (d5 / sc);
      e3 += (d3 / sc) * (d3 / sc);
    }
    if (e5 == T(0) && e3 == T(0)) return T(0);
    using std::fabs;
    using std::sqrt;
    return fabs(h) * e5 / sqrt((e5 + T(0.01) * e3) * T(n_));
  }

 private:
  int n_;
  std::vector<T> k_[Dop853Table::kStages], tmp_;
};

}  // namespace vines::host::reference
