//! The bevy_ecs layer (issue 5). Placeholder until built.
