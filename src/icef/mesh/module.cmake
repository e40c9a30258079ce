# Triangle meshes out of the fields (surface nets over a density grid), their simplification
# (meshoptimizer) and glTF 2.0 binary output (tinygltf): what `icef export` writes.
find_package(TinyGLTF REQUIRED)
find_package(meshoptimizer REQUIRED)
icef_module(mesh DEPS icef_io TinyGLTF::TinyGLTF meshoptimizer::meshoptimizer)
