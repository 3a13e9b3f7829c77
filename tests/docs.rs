//! The documentation says what the tools do: README.md and docs/TOOLS.md.
