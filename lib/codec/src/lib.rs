//! Level-image codecs.
