#version 450 core
// place.vert draws nothing; a program needs a fragment stage.
void main() {}
