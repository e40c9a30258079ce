icef_module(core DEPS Eigen3::Eigen OpenMP::OpenMP_CXX)
