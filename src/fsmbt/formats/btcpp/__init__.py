"""BehaviorTree.CPP XML: the reader and writer, and the trees SubTrees name in other files."""
