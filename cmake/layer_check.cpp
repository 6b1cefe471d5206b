// Linked with one layer's whole archive and only the layers below it (CMakeLists.txt,
// gmasim_layer_check_*): the link fails if the layer calls into a layer above it.
int main() { return 0; }
