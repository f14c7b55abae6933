/* productions of plant.l */
A --> F@Gr(2)
