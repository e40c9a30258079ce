#include "icef/math/types.h"

#include <sstream>

namespace icef {

std::string ToString(const Eigen::MatrixXd& m) {
  std::ostringstream os;
  os.precision(6);
  const bool vector = m.cols() == 1 || m.rows() == 1;
  os << "[";
  if (vector) {
    for (Eigen::Index i = 0; i < m.size(); ++i) os << (i ? ", " : "") << m.data()[i];
  } else {
    for (Eigen::Index r = 0; r < m.rows(); ++r) {
      os << (r ? ", [" : "[");
      for (Eigen::Index c = 0; c < m.cols(); ++c) os << (c ? ", " : "") << m(r, c);
      os << "]";
    }
  }
  os << "]";
  return os.str();
}

}  // namespace icef
