//! Sprite effects (in progress).
